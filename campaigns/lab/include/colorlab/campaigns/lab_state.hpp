#pragma once
// The state of the lab a script has asked for so far — lamps, dimmer, table, calibration, camera
// settings — rebuilt from the journal on replay. Before the first live step after a resume, the
// engine brings the real instruments to this state (a fresh process's drivers know nothing of
// what the previous process did), so the next reading is taken as if nothing had happened.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace colorlab::campaigns {

struct LabState {
  std::optional<std::vector<std::string>> lamps_on;  // nullopt: the script never switched lamps
  std::optional<double> dimmer_percent;
  bool table_used = false;
  std::optional<std::pair<double, double>> table_xy;
  bool head_down = false;
  std::optional<bool> paper_held;
  std::optional<std::string> spectro_mode;
  bool spectro_calibrated = false;
  nlohmann::json camera_settings;  // merged configure() arguments, null if never configured
  // Operator actions the simulated lab carried out (action → details, the last of each kind):
  // redone after a resume, because a fresh simulator has forgotten them. A person's actions stay done.
  std::map<std::string, nlohmann::json> done_by_hands;

  // Follows one completed call (live or replayed).
  void apply(const std::string& call, const nlohmann::json& args, const nlohmann::json& result);
  bool any_lamp_on() const { return lamps_on && !lamps_on->empty(); }
  nlohmann::json to_json() const;
};

}  // namespace colorlab::campaigns
