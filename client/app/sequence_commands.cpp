#include "sequence_commands.hpp"

#include <iostream>
#include <chrono>
#include <map>
#include <thread>

#include "colorlab/client/sse.hpp"
#include "colorlab/core/error.hpp"
#include "client_support.hpp"
#include "follow.hpp"

namespace colorlab::cli {

using nlohmann::json;

bool names_sequence(const client::ApiClient& api, const std::string& name) {
  for (const auto& c : api.get("/v1/campaigns").value("items", json::array())) {
    if (c.value("name", std::string()) == name && c.value("kind", std::string()) == "sequence") return true;
  }
  return false;
}

json queue_sequence(const client::ApiClient& api, const std::string& name, const std::vector<std::string>& params,
                    bool small, const std::string& on_failure, const std::string& idempotency_key, bool start) {
  json overrides = json::object();
  const json given = parse_params(params);  // kept: items() of a temporary would dangle
  for (const auto& [key, value] : given.items()) {
    auto dot = key.find('.');
    if (dot == std::string::npos || dot == 0 || dot + 1 == key.size()) {
      throw Error(ErrorClass::bad_parameter, "--param '" + key + "' of sequence " + name + " is not STEP.KEY=VALUE",
                  "colorlab campaigns lists the sequence's steps, e.g. -p cabinet-grid.rows=4");
    }
    overrides[key.substr(0, dot)][key.substr(dot + 1)] = value;
  }
  std::map<std::string, std::string> headers;
  if (!idempotency_key.empty()) headers["Idempotency-Key"] = idempotency_key;
  return api.post("/v1/queue",
                  {{"sequence", name}, {"small", small}, {"overrides", overrides}, {"on_failure", on_failure}, {"start", start}},
                  headers);
}

namespace {

bool ended(const json& group) {
  auto state = group.value("state", std::string());
  return state == "done" || state == "failed";
}

std::string item_states(const json& group) {
  std::string out;
  for (const auto& item : group["items"]) out += item.value("state", std::string()) + ",";
  return out;
}

// Blocks until the event stream says something about the group's items (or, on (re)subscribing, the
// group is seen to have changed since `group`).
void wait_for_change(const client::ApiClient& api, const json& group) {
  const std::string id = group["id"];
  const std::string before = item_states(group);
  bool changed = false;
  client::SseParser parser([&](const client::SseEvent& ev) {
    json data = json::parse(ev.data, nullptr, false);
    if (data.is_discarded()) return true;
    if (ev.event == "snapshot") {
      changed = item_states(api.get("/v1/queue/groups/" + id)) != before;
    } else if (ev.event == "queue") {
      const json& p = data.value("payload", json::object());
      changed = p.value("group_id", std::string()) == id ||
                (p.contains("item") && p["item"].value("group_id", json()) == json(id));
    }
    return !changed;
  });
  try {
    api.stream("/v1/events/stream", [&](std::string_view bytes) { return parser.feed(bytes); }, {});
  } catch (const Error& e) {
    if (e.cls() != ErrorClass::no_comms) throw;
  }
}

}  // namespace

json follow_group(const client::ApiClient& api, json group, bool quiet) {
  const std::string id = group["id"];
  std::string announced;
  for (int lost = 0;;) {
    try {
      group = api.get("/v1/queue/groups/" + id);
      if (ended(group)) break;
      json running;
      std::size_t index = 0;
      for (std::size_t i = 0; i < group["items"].size(); ++i) {
        const auto& item = group["items"][i];
        if (item["state"] == "running" && item["execution_id"].is_string()) {
          running = item;
          index = i + 1;
        }
      }
      if (running.is_object()) {
        if (!quiet && announced != running["id"]) {
          std::cerr << "[" << index << "/" << group["items"].size() << "] " << running.value("step", std::string())
                    << " (" << running.value("campaign", std::string()) << ")\n";
          announced = running["id"];
        }
        follow_execution(api, api.get("/v1/executions/" + running["execution_id"].get<std::string>()), quiet);
        continue;
      }
      wait_for_change(api, group);
      lost = 0;
    } catch (const Error& e) {
      // The daemon restarting: the queue goes on in it; look again.
      if (e.cls() != ErrorClass::no_comms || ++lost > 30) throw;
      std::this_thread::sleep_for(std::chrono::seconds(1));
    }
  }
  return group;
}

}  // namespace colorlab::cli
