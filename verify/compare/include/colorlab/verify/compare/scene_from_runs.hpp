#pragma once
// The light half of a MeasuredScene from stored runs as GET /v1/runs/{id} (with its measurements) gives them, placed
// in a rendering: what `colorlab verify` builds before it compares. The rendering is assumed to be made with the
// exported camera, i.e. the floor photograph's own view (docs/verify.md "Using it"), so a floor spot lies where the
// floor-luminance run's photograph saw it, scaled to the rendering's size.
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/verify/compare/light_from_runs.hpp"
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
};

// Each floor spot's region in a width × height rendering, from a floor-luminance photograph row's data
// (`P/<lamp>/D<level>`: width, height, corners_px, spot_mm): the spot's centre mapped through the floor homography,
// scaled to the rendering, and the square inscribed in its disc (at least one pixel). Error(bad_data) when the row
// lacks the geometry.
SpotRegion floor_spot_regions(const nlohmann::json& photograph, int width, int height, const FloorGeometry& floor = {});

// Builds the light half of the scene from runs (run documents with "campaign" and "measurements"): every
// cabinet-grid run's LS-110 spots and the floor-luminance run's map, both placed through that run's photograph.
// Error(bad_parameter) for a run of another campaign or no floor-luminance run (it alone says where the floor lies
// in the photograph), Error(not_found) when a run lacks the chosen lamp and level.
MeasuredScene scene_from_runs(const std::vector<nlohmann::json>& runs, int width, int height,
                              const RunsSceneOptions& options = {});

}  // namespace colorlab::verify
