#include "colorlab/campaigns/call_timing.hpp"

#include <algorithm>

namespace colorlab::campaigns {

using nlohmann::json;

namespace {

const json& options_arg(const json& args, std::size_t index) {
  static const json none = json::object();
  return args.is_array() && args.size() > index && args[index].is_object() ? args[index] : none;
}

}  // namespace

std::set<std::string> TimingKeys::cold_lamps() const {
  std::set<std::string> cold;
  std::set_difference(lit_.begin(), lit_.end(), warm_.begin(), warm_.end(), std::inserter(cold, cold.end()));
  return cold;
}

std::string TimingKeys::key(const std::string& call, const json& args) const {
  if (call == "wait_stable") {
    // A lamp just lit warms up for minutes; lamps already stable only fill one stability window.
    auto cold = cold_lamps();
    if (cold.empty()) return "wait_stable warm";
    std::string k = "wait_stable cold";
    for (const auto& l : cold) k += " " + l;
    return k;
  }
  if (call == "operator.request") {
    const json& spec = options_arg(args, 0);
    return "operator.request " + (spec.contains("action") && spec["action"].is_string() ? spec["action"].get<std::string>() : "?");
  }
  if (call == "camera.photograph_chart") return "camera.photograph_chart per frame and format";
  if (call == "camera.capture") return "camera.capture per frame";
  if (call == "camera.photograph_floor") return "camera.photograph_floor per frame";
  return call;
}

double TimingKeys::units(const std::string& call, const json& args) {
  const json& o = options_arg(args, 0);
  auto number = [&](const char* name, double fallback) {
    return o.contains(name) && o[name].is_number() ? std::max(1.0, o[name].get<double>()) : fallback;
  };
  if (call == "camera.photograph_chart") {
    double formats = o.contains("formats") && o["formats"].is_array() && !o["formats"].empty()
                         ? static_cast<double>(o["formats"].size())
                         : 4.0;  // photograph_chart's default: raw, tiff16, tiff8, jpeg
    return number("frames", 25.0) * formats;
  }
  if (call == "camera.capture") return number("frames", 1.0);
  if (call == "camera.photograph_floor") return number("frames", 8.0);  // photograph_floor's default
  return 1.0;
}

double TimingKeys::asked_wait_s(const std::string& call, const json& args) {
  if (call == "wait" && args.is_array() && !args.empty() && args[0].is_number()) return args[0].get<double>();
  if (call == "dimmer.set") {
    const json& o = options_arg(args, 1);
    if (o.contains("settle_s") && o["settle_s"].is_number()) return std::max(0.0, o["settle_s"].get<double>());
  }
  return 0.0;
}

void TimingKeys::follow(const std::string& call, const json& args, const json& result) {
  auto relight = [&](std::set<std::string> on) {
    // A lamp switched off forgets its warm-up; one that stays lit keeps it.
    std::set<std::string> still_warm;
    for (const auto& l : on) {
      if (lit_.count(l) && warm_.count(l)) still_warm.insert(l);
    }
    lit_ = std::move(on);
    warm_ = std::move(still_warm);
  };
  if (call == "lamps.select" || call == "lamps.set" || call == "lamps.off") {
    std::set<std::string> on;
    if (result.is_object() && result.contains("lamps_on") && result["lamps_on"].is_array()) {
      for (const auto& l : result["lamps_on"]) {
        if (l.is_string()) on.insert(l.get<std::string>());
      }
    } else if (call == "lamps.select" && !args.empty() && args[0].is_string()) {
      on.insert(args[0].get<std::string>());
    }
    relight(std::move(on));
  } else if (call == "wait_stable") {
    warm_ = lit_;
  }
}

}  // namespace colorlab::campaigns
