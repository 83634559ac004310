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

  // Follows one completed call (live or replayed): the call's row in the registry (lab_calls.hpp) says
  // what it changes.
  void apply(const std::string& call, const nlohmann::json& args, const nlohmann::json& result);
  bool any_lamp_on() const { return lamps_on && !lamps_on->empty(); }
  nlohmann::json to_json() const;
};

// What each call changes in the state, named by the registry's rows (lab_calls.cpp).
namespace lab_state_effects {
using nlohmann::json;
void lamps_select(LabState& s, const json& args, const json& result);
void lamps_set(LabState& s, const json& args, const json& result);
void lamps_off(LabState& s, const json& args, const json& result);
void dimmer_set(LabState& s, const json& args, const json& result);
void table_move(LabState& s, const json& args, const json& result);
void table_home(LabState& s, const json& args, const json& result);
void table_head_up(LabState& s, const json& args, const json& result);
void table_head_down(LabState& s, const json& args, const json& result);
void table_hold_paper(LabState& s, const json& args, const json& result);
// table.measure_at and table.read_patch: move, lower, measure, raise.
void table_measured_at(LabState& s, const json& args, const json& result);
void operator_request(LabState& s, const json& args, const json& result);
void spectro_mode(LabState& s, const json& args, const json& result);
void spectro_calibrate(LabState& s, const json& args, const json& result);
void camera_configure(LabState& s, const json& args, const json& result);
}  // namespace lab_state_effects

}  // namespace colorlab::campaigns
