#pragma once
// `colorlab scene RUN… -o DIR` (issue 23, docs/verify.md "The measured scene"): the measured scene as a
// renderer needs it — scene.json (cabinet geometry, each lamp's spectral radiance and level, the chart's
// placement with every patch's measured reflectance, the camera, the LS-110's absolute scale) and
// build_scene.py, which builds that scene in Blender 3.4 and renders it with Cycles.
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/verify/cabinet.hpp"
#include "colorlab/verify/camera_pose.hpp"
#include "colorlab/verify/lens_calibration.hpp"

namespace colorlab::verify {

struct SceneExportOptions {
  // Lamps lit in the scene; empty: every lamp the cabinet-grid run measured at `dimmer_percent` (D65 when
  // there is no cabinet-grid run).
  std::vector<std::string> lamps;
  double dimmer_percent = 100.0;
  // The lab's lens calibration (OpenCV's model, pixels of the located photograph) and where it comes from; without
  // it the camera's intrinsics are the nominal EOS 20D's (stated so in scene.json).
  std::optional<CameraIntrinsics> lens;
  std::string lens_source;
  // The lab's stored lens calibrations ([[lens]], lens_calibration.hpp), used when `lens` is not given: the one
  // named `lens_name`, else the only one for the located photograph's size (choose_lens). scene.json names it.
  std::vector<LensCalibration> lenses;
  std::string lens_name;
};

inline constexpr std::string_view scene_schema = "colorlab-scene/1";

// Builds scene.json from run documents as `GET /v1/runs/{id}/export?format=json` returns them ({run,
// measurements}): exactly one chart-read run (the patch spectra), at most one cabinet-grid run (each
// lamp's luminance, fitted to its LS-110 readings) and at most one characterize-camera run (the located chart on
// its photograph: the camera's pose). Throws Error(bad_parameter) for a run of another
// campaign, a missing chart-read, a lamp with neither readings nor a configured luminance, a UV lamp (no
// named spectrum to give a renderer), and Error(bad_data) for a malformed run.
nlohmann::json export_scene(const CabinetGeometry& cabinet, const std::vector<nlohmann::json>& runs,
                            const SceneExportOptions& options = {});

// Blender's script (verify/scene/build_scene.py), embedded.
std::string_view build_scene_script();

// Writes DIR/scene.json and DIR/build_scene.py (DIR is created). Throws Error(io_error) when it cannot.
void write_scene(const nlohmann::json& scene, const std::filesystem::path& dir);

}  // namespace colorlab::verify
