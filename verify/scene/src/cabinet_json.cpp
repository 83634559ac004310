#include "colorlab/verify/cabinet_json.hpp"

#include <tuple>

#include "colorlab/core/error.hpp"

namespace colorlab::verify {

using nlohmann::json;

json cabinet_to_json(const CabinetGeometry& c) {
  json emitters = json::array();
  for (const auto& e : c.emitters)
    emitters.push_back({
        {"lamp", e.lamp},
        {"center_mm", {e.x_mm, e.y_mm}},
        {"size_mm", {e.length_mm, e.width_mm}},
        {"luminance_cd_m2", e.luminance_cd_m2},
    });
  return {{"width_mm", c.width_mm},
          {"depth_mm", c.depth_mm},
          {"height_mm", c.height_mm},
          {"floor_reflectance", c.floor_reflectance},
          {"chart_center_mm", {c.chart_center_x_mm, c.chart_center_y_mm}},
          {"grid_pitch_mm", {c.grid_pitch_x_mm, c.grid_pitch_y_mm}},
          {"emitter", emitters}};
}

namespace {

[[noreturn]] void bad(const std::string& where, const std::string& what) {
  throw Error(ErrorClass::bad_data, where + ": " + what, "the cabinet is described in docs/verify.md, \"The measured scene\"");
}

double number(const json& j, const std::string& key, const std::string& where) {
  if (!j.contains(key) || !j[key].is_number()) bad(where, key + " must be a number");
  return j[key].get<double>();
}

std::pair<double, double> pair(const json& j, const std::string& key, const std::string& where) {
  if (!j.contains(key) || !j[key].is_array() || j[key].size() != 2 || !j[key][0].is_number() || !j[key][1].is_number())
    bad(where, key + " must be [x, y] in mm");
  return {j[key][0].get<double>(), j[key][1].get<double>()};
}

}  // namespace

CabinetGeometry cabinet_from_json(const json& j, const std::string& where) {
  if (!j.is_object()) bad(where, "the cabinet must be a JSON object");
  CabinetGeometry c;
  c.width_mm = number(j, "width_mm", where);
  c.depth_mm = number(j, "depth_mm", where);
  c.height_mm = number(j, "height_mm", where);
  c.floor_reflectance = number(j, "floor_reflectance", where);
  std::tie(c.chart_center_x_mm, c.chart_center_y_mm) = pair(j, "chart_center_mm", where);
  std::tie(c.grid_pitch_x_mm, c.grid_pitch_y_mm) = pair(j, "grid_pitch_mm", where);
  if (!j.contains("emitter") || !j["emitter"].is_array()) bad(where, "emitter must be an array");
  for (const auto& e : j["emitter"]) {
    if (!e.is_object() || !e.contains("lamp") || !e["lamp"].is_string()) bad(where, "each emitter needs a lamp name");
    CabinetEmitter m;
    m.lamp = e["lamp"].get<std::string>();
    std::tie(m.x_mm, m.y_mm) = pair(e, "center_mm", where + " emitter " + m.lamp);
    std::tie(m.length_mm, m.width_mm) = pair(e, "size_mm", where + " emitter " + m.lamp);
    m.luminance_cd_m2 = number(e, "luminance_cd_m2", where + " emitter " + m.lamp);
    c.emitters.push_back(m);
  }
  try {
    validate(c);
  } catch (const Error& e) {
    bad(where, e.what());
  }
  return c;
}

}  // namespace colorlab::verify
