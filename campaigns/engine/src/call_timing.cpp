#include "colorlab/campaigns/call_timing.hpp"

#include <algorithm>

#include "colorlab/campaigns/lab_calls.hpp"

namespace colorlab::campaigns {

using nlohmann::json;

std::set<std::string> TimingKeys::cold_lamps() const {
  std::set<std::string> cold;
  std::set_difference(lit_.begin(), lit_.end(), warm_.begin(), warm_.end(), std::inserter(cold, cold.end()));
  return cold;
}

std::string TimingKeys::key(const std::string& call, const json& args) const {
  const LabCall* row = find_lab_call(call);
  if (!row) return call;
  if (row->timing.lamps == LampEffect::settle) {
    // A lamp just lit warms up for minutes; lamps already stable only fill one stability window.
    auto cold = cold_lamps();
    if (cold.empty()) return call + " warm";
    std::string k = call + " cold";
    for (const auto& l : cold) k += " " + l;
    return k;
  }
  if (row->timing.key_detail) return call + " " + row->timing.key_detail(args);
  return call;
}

double TimingKeys::units(const std::string& call, const json& args) {
  const LabCall* row = find_lab_call(call);
  return row && row->timing.units ? row->timing.units(args) : 1.0;
}

double TimingKeys::asked_wait_s(const std::string& call, const json& args) {
  const LabCall* row = find_lab_call(call);
  return row && row->timing.asked_wait_s ? row->timing.asked_wait_s(args) : 0.0;
}

double TimingKeys::nominal_s(const std::string& key, double lamp_warmup_s, double stability_window_s) {
  const LabCall* row = find_lab_call(key.substr(0, key.find(' ')));
  if (!row) return 0.0;
  if (row->timing.lamps == LampEffect::settle) {
    return key.size() > row->name.size() && key.compare(row->name.size(), std::string::npos, " warm") == 0 ? stability_window_s
                                                                                                           : lamp_warmup_s;
  }
  return row->timing.nominal_s;
}

bool TimingKeys::warms_up(const std::string& call, const std::string& key) {
  const LabCall* row = find_lab_call(call);
  return row && row->timing.lamps == LampEffect::settle && key != call + " warm";
}

void TimingKeys::follow(const std::string& call, const json& args, const json& result) {
  const LabCall* row = find_lab_call(call);
  if (!row) return;
  if (row->timing.lamps == LampEffect::relight) {
    std::set<std::string> on;
    if (result.is_object() && result.contains("lamps_on") && result["lamps_on"].is_array()) {
      for (const auto& l : result["lamps_on"]) {
        if (l.is_string()) on.insert(l.get<std::string>());
      }
    } else if (!args.empty() && args[0].is_string()) {
      on.insert(args[0].get<std::string>());  // lamps.select named its one lamp
    }
    // A lamp switched off forgets its warm-up; one that stays lit keeps it.
    std::set<std::string> still_warm;
    for (const auto& l : on) {
      if (lit_.count(l) && warm_.count(l)) still_warm.insert(l);
    }
    lit_ = std::move(on);
    warm_ = std::move(still_warm);
  } else if (row->timing.lamps == LampEffect::settle) {
    warm_ = lit_;
  }
}

}  // namespace colorlab::campaigns
