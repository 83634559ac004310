#include "colorlab/verify/compare/scene_from_runs.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "colorlab/analysis/floor_luminance.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::verify {

using nlohmann::json;

namespace {

constexpr const char* kGrid = "cabinet-grid";
constexpr const char* kFloor = "floor-luminance";

std::string level_text(double percent) {
  char s[32];
  std::snprintf(s, sizeof s, "%g", percent);
  return s;
}

// The floor run's photograph row for the lamp and level (or its first when none is chosen yet).
const json* photograph_row(const json& run, const std::optional<LightSelection>& light) {
  for (const auto& m : run["measurements"]) {
    const std::string step = m.value("step", "");
    if (step.rfind("P/", 0) != 0 || !m.contains("data") || !m["data"].is_object()) continue;
    if (!light) return &m;
    if (step == "P/" + light->lamp + "/D" + level_text(light->dimmer_percent)) return &m;
  }
  return nullptr;
}

double number(const json& data, const char* key, const std::string& where) {
  if (!data.contains(key) || !data[key].is_number())
    throw Error(ErrorClass::bad_data, where + " has no number '" + std::string(key) + "'",
                "it must come from colorlab's floor-luminance campaign (docs/campaigns.md)");
  return data[key].get<double>();
}

// The photograph row's four floor corners, undistorted through the lens when one is given: they were measured on the
// distorted photograph, and the rendering is the pinhole of the same camera.
std::array<std::array<double, 2>, 4> pinhole_corners(const json& photograph, const std::optional<PhotographLens>& lens) {
  const std::string where = "the floor photograph row";
  const json& c = photograph.contains("corners_px") ? photograph["corners_px"] : json();
  if (!c.is_array() || c.size() != 4)
    throw Error(ErrorClass::bad_data, where + " has no four corners_px", "re-run floor-luminance with this colorlab");
  std::array<std::array<double, 2>, 4> corners{};
  for (std::size_t i = 0; i < 4; ++i) {
    if (!c[i].is_array() || c[i].size() != 2 || !c[i][0].is_number() || !c[i][1].is_number())
      throw Error(ErrorClass::bad_data, where + ": corner " + std::to_string(i) + " is not [x, y]");
    corners[i] = {c[i][0].get<double>(), c[i][1].get<double>()};
    if (lens) corners[i] = undistort_px(*lens, corners[i]);
  }
  return corners;
}

}  // namespace

FloorPlacement::FloorPlacement(const json& photograph, int width, int height, const FloorGeometry& floor,
                               const std::optional<PhotographLens>& lens)
    : map_(pinhole_corners(photograph, lens), floor.width_mm, floor.depth_mm), floor_(floor) {
  const std::string where = "the floor photograph row";
  const double pw = number(photograph, "width", where), ph = number(photograph, "height", where);
  const double spot_mm = number(photograph, "spot_mm", where);
  if (!(pw > 0 && ph > 0 && spot_mm > 0) || width <= 0 || height <= 0)
    throw Error(ErrorClass::bad_data, where + " or the rendering has no size");
  sx_ = width / pw, sy_ = height / ph, radius_mm_ = spot_mm / 2;
}

std::array<double, 2> FloorPlacement::rendering_px(double x_mm, double y_mm) const {
  // Pixel centres at integers on both sides: the photograph's pixel p covers the rendering's (p + ½)·s − ½.
  const auto p = map_.pixel_of(x_mm, y_mm);
  return {(p[0] + 0.5) * sx_ - 0.5, (p[1] + 0.5) * sy_ - 0.5};
}

PixelRect FloorPlacement::spot_region(int row, int col) const {
  const double x = (col + 0.5) * floor_.pitch_x_mm, y = (row + 0.5) * floor_.pitch_y_mm, r = radius_mm_;
  const auto c = rendering_px(x, y);
  // The disc's extent along each image axis, then the square inscribed in it: every sampled pixel lies on the spot.
  const auto xl = map_.pixel_of(x - r, y), xr = map_.pixel_of(x + r, y);
  const auto yf = map_.pixel_of(x, y - r), yb = map_.pixel_of(x, y + r);
  const double hx = std::hypot(xr[0] - xl[0], xr[1] - xl[1]) / 2 * sx_ / std::sqrt(2.0);
  const double hy = std::hypot(yb[0] - yf[0], yb[1] - yf[1]) / 2 * sy_ / std::sqrt(2.0);
  PixelRect rect;
  rect.w = std::max(1, static_cast<int>(std::lround(2 * hx)));
  rect.h = std::max(1, static_cast<int>(std::lround(2 * hy)));
  rect.x = static_cast<int>(std::lround(c[0] - (rect.w - 1) / 2.0));
  rect.y = static_cast<int>(std::lround(c[1] - (rect.h - 1) / 2.0));
  return rect;
}

SpotRegion floor_spot_regions(const json& photograph, int width, int height, const FloorGeometry& floor,
                              const std::optional<PhotographLens>& lens) {
  const auto placement = std::make_shared<const FloorPlacement>(photograph, width, height, floor, lens);
  return [placement](int row, int col) { return placement->spot_region(row, col); };
}

MeasuredScene scene_from_runs(const std::vector<json>& runs, int width, int height, const RunsSceneOptions& options) {
  const json* floor_run = nullptr;
  std::vector<const json*> grid_runs;
  for (const auto& run : runs) {
    const std::string campaign = run.value("campaign", ""), id = run.value("id", "");
    if (!run.contains("measurements") || !run["measurements"].is_array())
      throw Error(ErrorClass::bad_data, "run " + id + " came without its measurements");
    if (campaign == kFloor) {
      if (floor_run)
        throw Error(ErrorClass::bad_parameter, "two floor-luminance runs given (" + floor_run->value("id", "") + ", " + id + ")",
                    "verify against one floor map at a time");
      floor_run = &run;
    } else if (campaign == kGrid) {
      grid_runs.push_back(&run);
    } else {
      throw Error(ErrorClass::bad_parameter,
                  "run " + id + " is a " + (campaign.empty() ? std::string("?") : campaign) + " run, which gives no light to verify against",
                  "give cabinet-grid and floor-luminance runs for the light, characterize-camera and its chart-read for the colour");
    }
  }
  if (grid_runs.size() > 1)
    throw Error(ErrorClass::bad_parameter, "two cabinet-grid runs given", "verify against one LS-110 grid at a time");
  if (!floor_run)
    throw Error(ErrorClass::bad_parameter, "no floor-luminance run given",
                "the floor-luminance run's photograph says where the floor lies in the camera's view; give one with --against");

  std::optional<LightSelection> light = options.light;
  const json* photo = photograph_row(*floor_run, light);
  if (!photo) {
    if (light)
      throw Error(ErrorClass::not_found,
                  "the floor-luminance run has no photograph under " + light->lamp + " at " + level_text(light->dimmer_percent) + " %",
                  "pick a lamp and dimmer level the run photographed (its params: lamps, dimmer_levels)");
    throw Error(ErrorClass::bad_data, "the floor-luminance run has no photograph row (P/…)", "did it finish?");
  }
  const json& data = (*photo)["data"];
  if (!light) {
    LightSelection chosen;
    chosen.lamp = data.value("lamp", std::string());
    chosen.dimmer_percent = number(data, "dimmer_percent", "the floor photograph row");
    if (chosen.lamp.empty()) throw Error(ErrorClass::bad_data, "the floor photograph row names no lamp");
    light = chosen;
  }
  const SpotRegion region = floor_spot_regions(data, width, height, options.floor, options.lens);

  MeasuredScene scene;
  scene.runs.push_back(floor_run->value("id", ""));
  add_floor_luminance(scene, (*floor_run)["measurements"].get<std::vector<json>>(), *light, region);
  for (const auto* g : grid_runs) {
    scene.runs.push_back(g->value("id", ""));
    add_cabinet_grid(scene, (*g)["measurements"].get<std::vector<json>>(), *light, region);
  }
  const double pw = number(data, "width", "the floor photograph row"), ph = number(data, "height", "the floor photograph row");
  scene.floor_accuracy_px = options.corner_accuracy_px * std::max(width / pw, height / ph);
  return scene;
}

}  // namespace colorlab::verify
