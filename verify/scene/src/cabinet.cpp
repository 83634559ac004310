#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <string>

#include "colorlab/core/error.hpp"
#include "colorlab/verify/cabinet.hpp"

namespace colorlab::verify {
namespace {

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

[[noreturn]] void bad(const std::string& what) {
  throw Error(ErrorClass::bad_parameter, "cabinet: " + what, "see docs/verify.md, \"The measured scene\"");
}

std::string num(double v) {
  std::string s = std::to_string(v);
  s.erase(s.find_last_not_of('0') + 1);
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s;
}

}  // namespace

CabinetGeometry default_cabinet() {
  CabinetGeometry c;
  // Panels side by side, not overlapping, so a renderer never sees two coplanar emitters in one place.
  c.emitters = {
      {"D65", 600.0, 100.0, 1000.0, 100.0, 17000.0},
      {"A", 600.0, 200.0, 600.0, 80.0, 22000.0},
      {"TL84", 600.0, 300.0, 1000.0, 80.0, 23000.0},
      {"CWF", 600.0, 400.0, 1000.0, 80.0, 20000.0},
      {"UV", 600.0, 500.0, 1000.0, 60.0, 370.0},
  };
  return c;
}

void validate(const CabinetGeometry& c) {
  auto positive = [](double v, const char* name, double max) {
    if (!(v > 0.0 && v <= max)) bad(std::string(name) + " must be in (0, " + num(max) + "] mm, not " + num(v));
  };
  positive(c.width_mm, "width_mm", 10000.0);
  positive(c.depth_mm, "depth_mm", 10000.0);
  positive(c.height_mm, "height_mm", 10000.0);
  if (!(c.floor_reflectance >= 0.0 && c.floor_reflectance <= 1.0))
    bad("floor_reflectance must be within 0..1, not " + num(c.floor_reflectance));
  if (!(c.chart_center_x_mm >= 0.0 && c.chart_center_x_mm <= c.width_mm && c.chart_center_y_mm >= 0.0 &&
        c.chart_center_y_mm <= c.depth_mm))
    bad("chart_center_mm [" + num(c.chart_center_x_mm) + ", " + num(c.chart_center_y_mm) + "] is off the floor");
  positive(c.grid_pitch_x_mm, "grid_pitch_mm[0]", c.width_mm);
  positive(c.grid_pitch_y_mm, "grid_pitch_mm[1]", c.depth_mm);
  static const std::set<std::string> known{"D65", "TL84", "CWF", "A", "UV"};
  std::set<std::string> seen;
  for (const auto& e : c.emitters) {
    const std::string lamp = upper(e.lamp);
    const std::string who = "emitter \"" + e.lamp + "\"";
    if (!known.count(lamp)) bad(who + ": lamp must be one of D65, TL84, CWF, A, UV");
    if (!seen.insert(lamp).second) bad(who + " is given twice (one emitter per lamp)");
    if (!(e.length_mm > 0.0) || !(e.width_mm > 0.0)) bad(who + ": size_mm must be two positive lengths");
    const bool inside = e.x_mm - e.length_mm / 2 >= 0.0 && e.x_mm + e.length_mm / 2 <= c.width_mm &&
                        e.y_mm - e.width_mm / 2 >= 0.0 && e.y_mm + e.width_mm / 2 <= c.depth_mm;
    if (!inside)
      bad(who + " reaches outside the " + num(c.width_mm) + " × " + num(c.depth_mm) + " mm ceiling");
    if (!(e.luminance_cd_m2 >= 0.0) || !std::isfinite(e.luminance_cd_m2))
      bad(who + ": luminance_cd_m2 must be >= 0 (0 = unknown)");
  }
}

const CabinetEmitter* emitter_of(const CabinetGeometry& c, const std::string& lamp) {
  const std::string want = upper(lamp);
  for (const auto& e : c.emitters)
    if (upper(e.lamp) == want) return &e;
  return nullptr;
}

}  // namespace colorlab::verify
