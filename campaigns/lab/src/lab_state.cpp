#include "colorlab/campaigns/lab_state.hpp"

namespace colorlab::campaigns {

using nlohmann::json;

void LabState::apply(const std::string& call, const json& args, const json& result) {
  if (call == "lamps.select") {
    lamps_on = std::vector<std::string>{args[0].get<std::string>()};
  } else if (call == "lamps.set") {
    std::vector<std::string> on;
    for (const auto& l : args[0]) on.push_back(l.get<std::string>());
    lamps_on = on;
  } else if (call == "lamps.off") {
    lamps_on = std::vector<std::string>{};
  } else if (call == "dimmer.set") {
    dimmer_percent = args[0].get<double>();
  } else if (call == "table.move") {
    table_used = true;
    table_xy = std::make_pair(args[0].get<double>(), args[1].get<double>());
  } else if (call == "table.home") {
    table_used = true;
    table_xy = std::make_pair(0.0, 0.0);
    head_down = false;
  } else if (call == "table.head_up") {
    table_used = true;
    head_down = false;
  } else if (call == "table.head_down") {
    table_used = true;
    head_down = true;
  } else if (call == "table.hold_paper") {
    table_used = true;
    paper_held = args[0].get<bool>();
  } else if (call == "operator.request") {
    if (result.is_object() && result.value("by", std::string()) == "simulator") {
      done_by_hands[result.value("action", std::string())] = result.value("details", json::object());
    }
  } else if (call == "table.measure_at" || call == "table.read_patch") {
    // Move, lower, measure, raise: the head ends up over the patch.
    table_used = true;
    table_xy = std::make_pair(args[0].get<double>(), args[1].get<double>());
    head_down = false;
  } else if (call == "spectro.mode") {
    spectro_mode = args[0].get<std::string>();
    spectro_calibrated = false;  // a calibration is per mode
  } else if (call == "spectro.calibrate") {
    spectro_calibrated = true;
    // The Spectrolino on a table calibrates on the tile: the head is no longer where it was.
    if (table_used) {
      table_xy.reset();
      head_down = false;
    }
  } else if (call == "camera.configure") {
    if (camera_settings.is_null()) camera_settings = json::object();
    camera_settings.update(args[0]);
  }
}

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
