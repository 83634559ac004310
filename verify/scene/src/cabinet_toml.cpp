#include "colorlab/verify/cabinet_toml.hpp"

#include <string>
#include <tuple>

#include "colorlab/core/error.hpp"

namespace colorlab::verify {
namespace {

[[noreturn]] void bad(const std::filesystem::path& file, const toml::node& n, const std::string& what) {
  throw Error(ErrorClass::bad_parameter, file.string() + ":" + std::to_string(n.source().begin.line) + ": " + what,
              "see docs/verify.md, \"The measured scene\"");
}

double number(const std::filesystem::path& file, const toml::node& n, const std::string& key) {
  auto v = n.value<double>();
  if (!v) bad(file, n, key + " must be a number");
  return *v;
}

std::pair<double, double> pair(const std::filesystem::path& file, const toml::node& n, const std::string& key) {
  auto a = n.as_array();
  auto x = a && a->size() == 2 ? (*a)[0].value<double>() : std::nullopt;
  auto y = a && a->size() == 2 ? (*a)[1].value<double>() : std::nullopt;
  if (!x || !y) bad(file, n, key + " must be [x, y] in mm");
  return {*x, *y};
}

CabinetEmitter emitter(const std::filesystem::path& file, const toml::node& n) {
  auto t = n.as_table();
  if (!t) bad(file, n, "cabinet.emitter entries must be tables");
  CabinetEmitter e;
  bool centre = false, size = false;
  for (const auto& [k, v] : *t) {
    const std::string key(k.str());
    if (key == "lamp") {
      auto s = v.value<std::string>();
      if (!s) bad(file, v, "cabinet.emitter.lamp must be a lamp name");
      e.lamp = *s;
    } else if (key == "center_mm") {
      std::tie(e.x_mm, e.y_mm) = pair(file, v, "cabinet.emitter.center_mm");
      centre = true;
    } else if (key == "size_mm") {
      std::tie(e.length_mm, e.width_mm) = pair(file, v, "cabinet.emitter.size_mm");
      size = true;
    } else if (key == "luminance_cd_m2") {
      e.luminance_cd_m2 = number(file, v, "cabinet.emitter.luminance_cd_m2");
    } else {
      bad(file, v, "unknown key cabinet.emitter." + key + " (lamp, center_mm, size_mm, luminance_cd_m2)");
    }
  }
  if (e.lamp.empty() || !centre || !size) bad(file, n, "cabinet.emitter needs lamp, center_mm and size_mm");
  return e;
}

}  // namespace

CabinetGeometry cabinet_from_toml(const toml::table& t, const std::filesystem::path& file) {
  CabinetGeometry c = default_cabinet();
  bool emitters = false;
  for (const auto& [k, v] : t) {
    const std::string key(k.str());
    if (key == "width_mm") c.width_mm = number(file, v, "cabinet.width_mm");
    else if (key == "depth_mm") c.depth_mm = number(file, v, "cabinet.depth_mm");
    else if (key == "height_mm") c.height_mm = number(file, v, "cabinet.height_mm");
    else if (key == "floor_reflectance") c.floor_reflectance = number(file, v, "cabinet.floor_reflectance");
    else if (key == "chart_center_mm") std::tie(c.chart_center_x_mm, c.chart_center_y_mm) = pair(file, v, "cabinet.chart_center_mm");
    else if (key == "grid_pitch_mm") std::tie(c.grid_pitch_x_mm, c.grid_pitch_y_mm) = pair(file, v, "cabinet.grid_pitch_mm");
    else if (key == "emitter") {
      auto a = v.as_array();
      if (!a) bad(file, v, "cabinet.emitter must be an array of tables ([[cabinet.emitter]])");
      if (!emitters) c.emitters.clear();
      emitters = true;
      for (const auto& e : *a) c.emitters.push_back(emitter(file, e));
    } else {
      bad(file, v, "unknown key cabinet." + key + " (width_mm, depth_mm, height_mm, floor_reflectance, chart_center_mm, grid_pitch_mm, emitter)");
    }
  }
  try {
    validate(c);
  } catch (const Error& e) {
    bad(file, t, e.what());
  }
  return c;
}

CabinetGeometry cabinet_from_file(const std::filesystem::path& file) {
  toml::table doc;
  try {
    doc = toml::parse_file(file.string());
  } catch (const toml::parse_error& e) {
    throw Error(ErrorClass::bad_parameter,
                file.string() + ":" + std::to_string(e.source().begin.line) + ": " + std::string(e.description()),
                "see docs/verify.md, \"The measured scene\"");
  }
  const auto* node = doc.get("cabinet");
  if (!node) return default_cabinet();
  const auto* t = node->as_table();
  if (!t) bad(file, *node, "[cabinet] must be a table");
  return cabinet_from_toml(*t, file);
}

}  // namespace colorlab::verify
