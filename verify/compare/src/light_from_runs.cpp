#include "colorlab/verify/compare/light_from_runs.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "colorlab/core/error.hpp"

namespace colorlab::verify {
namespace {

// The step's prefix for a lamp and level, as the campaigns write it (Lua's %g).
std::string prefix(const char* kind, const LightSelection& w) {
  char level[32];
  std::snprintf(level, sizeof level, "%g", w.dimmer_percent);
  return std::string(kind) + "/" + w.lamp + "/D" + level;
}

bool spot_of(const std::string& step, const std::string& pre, int& row, int& col) {
  if (step.rfind(pre + "/r", 0) != 0) return false;
  char tail = 0;
  return std::sscanf(step.c_str() + pre.size() + 1, "r%dc%d%c", &row, &col, &tail) == 2;
}

std::string at(const LightSelection& w) {
  std::ostringstream s;
  s << w.lamp << " at " << w.dimmer_percent << " %";
  return s.str();
}

}  // namespace

void add_cabinet_grid(MeasuredScene& scene, const std::vector<nlohmann::json>& measurements, const LightSelection& which,
                      const SpotRegion& region) {
  const std::string pre = prefix("L", which);
  std::vector<SpotMeasurement> spots;
  double pooled = 0;
  long pooled_n = 0;
  for (const auto& m : measurements) {
    int row = 0, col = 0;
    if (!spot_of(m.value("step", ""), pre, row, col)) continue;
    const auto& data = m.contains("data") ? m["data"] : nlohmann::json::object();
    std::vector<double> r;
    if (data.contains("readings"))
      for (const auto& x : data["readings"]) r.push_back(x.get<double>());
    if (r.empty() && m.contains("value") && m["value"].is_number()) r.push_back(m["value"].get<double>());
    if (r.empty())
      throw Error(ErrorClass::bad_data, "cabinet-grid step " + m.value("step", "") + " has no reading");
    double mean = 0;
    for (double x : r) mean += x;
    mean /= static_cast<double>(r.size());
    if (r.size() >= 2 && mean > 0) {
      double ss = 0;
      for (double x : r) ss += (x - mean) * (x - mean);
      pooled += ss / (mean * mean);
      pooled_n += static_cast<long>(r.size()) - 1;
    }
    SpotMeasurement s;
    s.row = row;
    s.col = col;
    s.luminance_cd_m2 = mean;
    s.readings = static_cast<int>(r.size());
    s.rendering_region = region(row, col);
    spots.push_back(s);
  }
  if (spots.empty())
    throw Error(ErrorClass::not_found, "the cabinet-grid run has no LS-110 reading under " + at(which),
                "pick a lamp and dimmer level the run measured (its params: lamps, dimmer_levels)");
  // Two readings per spot say little about one spot; pooled over the grid they say the meter's repeatability.
  const double relative = pooled_n > 0 ? std::sqrt(pooled / static_cast<double>(pooled_n)) : kLs110RelativeSd;
  for (auto& s : spots) s.reading_sd = std::max(relative, 1e-6) * s.luminance_cd_m2;
  scene.spots.insert(scene.spots.end(), spots.begin(), spots.end());
  if (scene.lamp.empty()) scene.lamp = which.lamp;
  if (scene.lamp_drift_bound <= 0) scene.lamp_drift_bound = kLampDriftBound;
}

void add_floor_luminance(MeasuredScene& scene, const std::vector<nlohmann::json>& measurements,
                         const LightSelection& which, const SpotRegion& region) {
  const std::string pre = prefix("F", which), photo = prefix("P", which);
  double residual_sq = 0;
  int residual_n = 0;
  std::vector<FloorCell> cells;
  for (const auto& m : measurements) {
    const std::string step = m.value("step", "");
    if (step == photo && m.contains("data") && m["data"].contains("calibration")) {
      for (const auto& c : m["data"]["calibration"]) {
        const double r = c.value("residual_pct", 0.0) / 100.0;
        residual_sq += r * r;
        ++residual_n;
      }
      if (m["data"].contains("grid_rows")) scene.floor_rows = m["data"]["grid_rows"].get<int>();
      if (m["data"].contains("grid_cols")) scene.floor_cols = m["data"]["grid_cols"].get<int>();
      continue;
    }
    int row = 0, col = 0;
    if (!spot_of(step, pre, row, col)) continue;
    if (!m.contains("value") || !m["value"].is_number())
      throw Error(ErrorClass::bad_data, "floor-luminance step " + step + " has no luminance");
    FloorCell f;
    f.row = row;
    f.col = col;
    f.luminance_cd_m2 = m["value"].get<double>();
    f.rendering_region = region(row, col);
    cells.push_back(f);
  }
  if (cells.empty())
    throw Error(ErrorClass::not_found, "the floor-luminance run has no map under " + at(which),
                "pick a lamp and dimmer level the run photographed (its params: lamps, dimmer_levels)");
  const double rms = residual_n > 0 ? std::sqrt(residual_sq / residual_n) : 0.0;
  if (!(rms > 0))
    throw Error(ErrorClass::bad_data,
                "the floor map's flat field has no calibration residual to judge it by (" +
                    std::to_string(residual_n) + " calibration spots)",
                "run floor-luminance with more calibration spots than the flat field has terms (degree + 2)");
  for (auto& c : cells) c.relative_sd = rms;
  scene.floor.insert(scene.floor.end(), cells.begin(), cells.end());
  if (scene.lamp.empty()) scene.lamp = which.lamp;
  if (scene.lamp_drift_bound <= 0) scene.lamp_drift_bound = kLampDriftBound;
}

}  // namespace colorlab::verify
