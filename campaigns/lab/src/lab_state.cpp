#include "colorlab/campaigns/lab_state.hpp"

#include "colorlab/campaigns/lab_calls.hpp"

namespace colorlab::campaigns {

using nlohmann::json;

void LabState::apply(const std::string& call, const json& args, const json& result) {
  const LabCall* row = find_lab_call(call);
  if (row && row->state_effect) row->state_effect(*this, args, result);
}

namespace lab_state_effects {

void lamps_select(LabState& s, const json& args, const json&) { s.lamps_on = std::vector<std::string>{args[0].get<std::string>()}; }

void lamps_set(LabState& s, const json& args, const json&) {
  std::vector<std::string> on;
  for (const auto& l : args[0]) on.push_back(l.get<std::string>());
  s.lamps_on = on;
}

void lamps_off(LabState& s, const json&, const json&) { s.lamps_on = std::vector<std::string>{}; }

void dimmer_set(LabState& s, const json& args, const json&) { s.dimmer_percent = args[0].get<double>(); }

void table_move(LabState& s, const json& args, const json&) {
  s.table_used = true;
  s.table_xy = std::make_pair(args[0].get<double>(), args[1].get<double>());
}

void table_home(LabState& s, const json&, const json&) {
  s.table_used = true;
  s.table_xy = std::make_pair(0.0, 0.0);
  s.head_down = false;
}

void table_head_up(LabState& s, const json&, const json&) {
  s.table_used = true;
  s.head_down = false;
}

void table_head_down(LabState& s, const json&, const json&) {
  s.table_used = true;
  s.head_down = true;
}

void table_hold_paper(LabState& s, const json& args, const json&) {
  s.table_used = true;
  s.paper_held = args[0].get<bool>();
}

void table_measured_at(LabState& s, const json& args, const json&) {
  // The head ends up raised over the patch.
  s.table_used = true;
  s.table_xy = std::make_pair(args[0].get<double>(), args[1].get<double>());
  s.head_down = false;
}

void operator_request(LabState& s, const json&, const json& result) {
  if (result.is_object() && result.value("by", std::string()) == "simulator") {
    s.done_by_hands[result.value("action", std::string())] = result.value("details", json::object());
  }
}

void spectro_mode(LabState& s, const json& args, const json&) {
  s.spectro_mode = args[0].get<std::string>();
  s.spectro_calibrated = false;  // a calibration is per mode
}

void spectro_calibrate(LabState& s, const json&, const json&) {
  s.spectro_calibrated = true;
  // The Spectrolino on a table calibrates on the tile: the head is no longer where it was.
  if (s.table_used) {
    s.table_xy.reset();
    s.head_down = false;
  }
}

void camera_configure(LabState& s, const json& args, const json&) {
  if (s.camera_settings.is_null()) s.camera_settings = json::object();
  s.camera_settings.update(args[0]);
}

}  // namespace lab_state_effects

json LabState::to_json() const {
  json j = json::object();
  if (lamps_on) j["lamps_on"] = *lamps_on;
  if (dimmer_percent) j["dimmer_percent"] = *dimmer_percent;
  if (table_xy) j["table_mm"] = {table_xy->first, table_xy->second};
  if (table_used) j["head_down"] = head_down;
  if (paper_held) j["paper_held"] = *paper_held;
  if (spectro_mode) j["spectro_mode"] = *spectro_mode;
  j["spectro_calibrated"] = spectro_calibrated;
  if (!camera_settings.is_null()) j["camera"] = camera_settings;
  return j;
}

}  // namespace colorlab::campaigns
