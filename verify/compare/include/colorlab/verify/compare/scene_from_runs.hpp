#pragma once
// The light half of a MeasuredScene from stored runs as GET /v1/runs/{id} (with its measurements) gives them, placed
// in a rendering: what `colorlab verify` builds before it compares. The rendering is assumed to be made with the
// exported camera, i.e. the floor photograph's own view (docs/verify.md "Using it"), so a floor spot lies where the
// floor-luminance run's photograph saw it, scaled to the rendering's size — through the lens calibration when one is
// given: the photograph is distorted, the rendering is the same camera's pinhole.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/analysis/floor_luminance.hpp"
#include "colorlab/verify/compare/light_from_runs.hpp"
#include "colorlab/verify/compare/photograph_lens.hpp"
#include "colorlab/verify/compare/verification.hpp"

namespace colorlab::verify {

// The §6.2 floor and its spot grid, as floor-luminance photographs it (campaigns/floor_photograph.hpp's defaults):
// spot (row, col) at ((col + ½)·60 mm, (row + ½)·54 mm) from the front-left corner of a 1200 × 600 mm floor.
struct FloorGeometry {
  double width_mm = 1200, depth_mm = 600, pitch_x_mm = 60, pitch_y_mm = 54;
};

struct RunsSceneOptions {
  std::optional<LightSelection> light;  // absent: the floor-luminance run's first lamp and level (else the grid's)
  // How well the floor's corners were measured on the photograph, one σ in its pixels: the floor homography's
  // accuracy, carried to the rendering's pixels as its misregistration.
  double corner_accuracy_px = 0.5;
  FloorGeometry floor;
  // The floor photograph's lens (the lab's calibration for its size). Absent: the photograph is taken as a pinhole,
  // and a distorted lens misplaces the spots towards the frame's edges (docs/verify.md, "Where each spot is").
  std::optional<PhotographLens> lens;
};

// Where the floor lies in a width × height rendering made with the floor photograph's camera, from the photograph
// row's data (`P/<lamp>/D<level>`: width, height, corners_px): the four corners — undistorted through the lens when
// one is given, so they are the pinhole camera's — give the plane homography, exact for the pinhole rendering;
// positions scale from the photograph's pixels to the rendering's (pixel centres at integers on both sides).
// Error(bad_data) when the row lacks the geometry, and for a corner the lens cannot undistort.
class FloorPlacement {
 public:
  FloorPlacement(const nlohmann::json& photograph, int width, int height, const FloorGeometry& floor = {},
                 const std::optional<PhotographLens>& lens = std::nullopt);
  std::array<double, 2> rendering_px(double x_mm, double y_mm) const;
  // The spot's square inscribed in its disc (spot_mm of the row) as the rendering sees it, at least one pixel.
  PixelRect spot_region(int row, int col) const;

 private:
  analysis::FloorMap map_;  // floor mm → the pinhole photograph's pixels
  double sx_ = 1, sy_ = 1, radius_mm_ = 10;
  FloorGeometry floor_;
};

// Each floor spot's region in a width × height rendering, from a floor-luminance photograph row's data
// (`P/<lamp>/D<level>`: width, height, corners_px, spot_mm): the spot's centre mapped through the floor homography,
// scaled to the rendering, and the square inscribed in its disc (at least one pixel). Error(bad_data) when the row
// lacks the geometry.
SpotRegion floor_spot_regions(const nlohmann::json& photograph, int width, int height, const FloorGeometry& floor = {},
                              const std::optional<PhotographLens>& lens = std::nullopt);

// Builds the light half of the scene from runs (run documents with "campaign" and "measurements"): every
// cabinet-grid run's LS-110 spots and the floor-luminance run's map, both placed through that run's photograph.
// Error(bad_parameter) for a run of another campaign or no floor-luminance run (it alone says where the floor lies
// in the photograph), Error(not_found) when a run lacks the chosen lamp and level.
MeasuredScene scene_from_runs(const std::vector<nlohmann::json>& runs, int width, int height,
                              const RunsSceneOptions& options = {});

}  // namespace colorlab::verify
