// Lab::operator_request: lab.operator.request{action=, prompt=, options=, default=, timeout_s=, details=}.
#include <algorithm>
#include <chrono>

#include <boost/asio/steady_timer.hpp>
#include <boost/asio/use_awaitable.hpp>

#include "colorlab/campaigns/lab.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/core/ids.hpp"
#include "colorlab/core/log.hpp"

namespace colorlab::campaigns {

namespace asio = boost::asio;
using nlohmann::json;

namespace {

Error bad(const std::string& what) {
  return Error(ErrorClass::script_error, "lab.operator.request: " + what,
               "e.g. lab.operator.request{action=\"load_chart\", prompt=\"Load the SG on the table\", "
               "options={\"done\",\"skip\"}, default=\"skip\", timeout_s=1800}");
}

}  // namespace

OperatorRequest parse_operator_request(const json& spec) {
  OperatorRequest r;
  if (!spec.is_object()) throw bad("takes a table");
  for (const auto& [key, value] : spec.items()) {
    if (key != "action" && key != "prompt" && key != "options" && key != "default" && key != "timeout_s" && key != "details") {
      throw bad("unknown field '" + key + "' (action, prompt, options, default, timeout_s, details)");
    }
  }
  if (!spec.contains("action") || !spec["action"].is_string() || spec["action"].get<std::string>().empty() ||
      spec["action"].get<std::string>().size() > 64) {
    throw bad("action (a word of 1 to 64 characters, such as \"aim_meter\") is required");
  }
  r.action = spec["action"].get<std::string>();
  if (!spec.contains("prompt") || !spec["prompt"].is_string() || spec["prompt"].get<std::string>().empty()) {
    throw bad("prompt (what the operator should do, in words) is required");
  }
  r.prompt = spec["prompt"].get<std::string>();
  if (spec.contains("options")) {
    if (!spec["options"].is_array() || spec["options"].empty()) throw bad("options must be a list of answers");
    for (const auto& o : spec["options"]) {
      if (!o.is_string() || o.get<std::string>().empty()) throw bad("every option must be a non-empty string");
      r.options.push_back(o.get<std::string>());
    }
  } else {
    r.options = {"done"};
  }
  r.default_option = spec.value("default", r.options.front());
  if (std::find(r.options.begin(), r.options.end(), r.default_option) == r.options.end()) {
    throw bad("the default '" + r.default_option + "' is not one of the options");
  }
  r.timeout_s = 1800;
  if (spec.contains("timeout_s")) {
    if (!spec["timeout_s"].is_number() || !(spec["timeout_s"].get<double>() >= 0 && spec["timeout_s"].get<double>() <= 7 * 86400)) {
      throw bad("timeout_s must be a number of lab seconds from 0 to 604800");
    }
    r.timeout_s = spec["timeout_s"].get<double>();
  }
  r.details = spec.contains("details") ? spec["details"] : json::object();
  if (!r.details.is_object()) {
    if (r.details.is_array() && r.details.empty()) r.details = json::object();
    else throw bad("details must be a table of named values");
  }
  return r;
}

asio::awaitable<json> Lab::operator_request(const json& spec, const ExecutionControl& control) {
  OperatorRequest r = parse_operator_request(spec);
  if (hands_) {
    auto done = co_await hands_->perform(r.action, r.details);
    if (done) {
      log::info("lab", "operator action '" + r.action + "' done by the simulated lab");
      co_return json{{"answer", r.options.front()}, {"by", "simulator"}, {"action", r.action}, {"details", r.details}};
    }
  }
  if (!desk_) {
    throw Error(ErrorClass::needs_operator, "the campaign asks the operator: " + r.prompt,
                "this lab has no operator desk; run the campaign under colorlabd");
  }
  const auto wall_timeout = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(r.timeout_s / options_.time_scale));
  r.id = new_uuid_v7();
  r.execution_id = control.execution_id;
  r.posted_at = now_iso8601();
  r.deadline = iso8601_utc(std::chrono::system_clock::now() +
                           std::chrono::duration_cast<std::chrono::system_clock::duration>(wall_timeout));
  const std::string id = desk_->post(r).id;
  const auto deadline = std::chrono::steady_clock::now() + wall_timeout;
  for (;;) {
    if (auto answered = desk_->take_answered(id)) {
      co_return json{{"answer", *answered->answer}, {"by", answered->answered_by}, {"action", r.action}, {"details", r.details}};
    }
    if (control.requested()) {
      desk_->withdraw(id, control.reason);
      throw Error(ErrorClass::aborted, "operator request withdrawn: " + control.reason);
    }
    if (std::chrono::steady_clock::now() >= deadline) {
      desk_->take_default(id);
      continue;
    }
    asio::steady_timer t(executor_, std::min<std::chrono::steady_clock::duration>(
                                        deadline - std::chrono::steady_clock::now() + std::chrono::milliseconds(1),
                                        std::chrono::milliseconds(50)));
    co_await t.async_wait(asio::use_awaitable);
  }
}

}  // namespace colorlab::campaigns
