#include "colorlab/client/runs.hpp"

#include "colorlab/protocol/api.hpp"

namespace colorlab::client {

using nlohmann::json;

json fetch_measurements(const ApiClient& api, const std::string& run_id, const std::string& query) {
  json all = json::array();
  std::string target = "/v1/runs/" + run_id + "/measurements?limit=" + std::to_string(protocol::kMaxMeasurementPageLimit) +
                       (query.empty() ? "" : "&" + query);
  for (;;) {
    json page = api.get(target);
    for (auto& m : page["items"]) all.push_back(std::move(m));
    if (!page.contains("next_cursor") || page["next_cursor"].is_null()) break;
    target = "/v1/runs/" + run_id + "/measurements?limit=" + std::to_string(protocol::kMaxMeasurementPageLimit) +
             (query.empty() ? "" : "&" + query) + "&cursor=" + page["next_cursor"].get<std::string>();
  }
  return all;
}

json fetch_run(const ApiClient& api, const std::string& run_id) {
  json run = api.get("/v1/runs/" + run_id);
  run["measurements"] = fetch_measurements(api, run_id);
  return run;
}

}  // namespace colorlab::client
