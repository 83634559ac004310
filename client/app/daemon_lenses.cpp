#include "daemon_lenses.hpp"

#include "colorlab/core/error.hpp"

namespace colorlab::cli {

std::optional<std::vector<verify::LensCalibration>> daemon_lenses(const client::ApiClient& api) {
  nlohmann::json answer;
  try {
    answer = api.get("/v1/lab/lenses");
  } catch (const client::ApiError& e) {
    if (e.problem().status == 404) return std::nullopt;
    throw;
  }
  if (!answer.is_object() || !answer.contains("items") || !answer["items"].is_array())
    throw Error(ErrorClass::bad_data, "GET /v1/lab/lenses: no items in the daemon's answer", "give the lens with --lens");
  std::vector<verify::LensCalibration> lenses;
  for (const auto& i : answer["items"]) lenses.push_back(verify::lens_from_json(i, "GET /v1/lab/lenses"));
  return lenses;
}

}  // namespace colorlab::cli
