#pragma once
// The colour half of a MeasuredScene from stored runs (issue 23, docs/verify.md "Using it"): a characterize-camera
// run (the raw photograph's patch values, its selected mapping, the black box) and the chart-read run it was fitted
// against (the patches' reflectance spectra), with the chart located in the rendering by the project's chart
// locator. Its own target (colorlab_verify_colour): the locator needs OpenCV, which the engine does not.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/verify/compare/scene_from_runs.hpp"
#include "colorlab/verify/compare/verification.hpp"

namespace colorlab::verify {

// The CIE illuminant a cabinet lamp's spectrum is taken to be (as characterize-camera's black box takes it):
// D65, A, TL84 = F11, CWF = F2. Error(bad_parameter) for a lamp without one (UV).
std::string illuminant_of_lamp(const std::string& lamp);

// §7.3's characterization: the run's selected raw mapping (method and target as stored) fitted again on the run's
// raw patch values against the chart-read's reflectances under the lamp's standard illuminant (XYZ, the lamp's
// perfect diffuser at Y = 100) — the stored fit targets D50, and refitting to the lamp's own colorimetry carries it
// to the lamp's white exactly instead of through a chromatic adaptation transform. Its per-patch error is a
// leave-one-out refit of the same method on the same data (a spline at the λ of the fit on every patch, as
// characterize-camera's own cross-validation does). `seconds` reports the LOO's wall time.
struct RefitCharacterization {
  Characterization characterization;
  std::vector<std::string> ids;  // training patches, in the run's order
  double loo_mean_de00 = 0;      // mean of the held-out ΔE00 (for the record)
  double seconds = 0;
};
RefitCharacterization refit_characterization(const nlohmann::json& characterize_run, const nlohmann::json& chart_read_run,
                                             const std::string& lamp);

// §7.4's black box as the run stored it: the sensitivities (relative, green peak 1) and each training patch's
// held-out residual in counts with its raw value. Error(not_found) when the run fitted none (not_fitted says why).
BlackBox stored_black_box(const nlohmann::json& characterize_run);

// Each chart patch's sampled region in the rendering, found by analysis::locate_chart on the rendering's luminance
// (the chart-read's Y telling which way up the chart is), in the layout's order with ids; `accuracy_px` is the fit's
// reprojection RMS, the locator's own statement of where the patches are. Error(needs_operator) when it is not found.
struct ChartInRendering {
  std::vector<std::string> ids;
  std::vector<PixelRect> regions;
  double accuracy_px = 0;
  double confidence = 0;
};
ChartInRendering locate_chart_in_rendering(const Rendering& rendering, const nlohmann::json& chart_read_run);

// Adds the patches (raw values, regions in the rendering), the characterization and, when the run has it, the
// black box. Frame noise is left at zero: the compared photograph is the one the characterization was fitted and
// cross-validated on, so its noise is already inside each patch's held-out error (docs/verify.md).
// Returns what was read, for the result: the characterization's name, its LOO mean ΔE00 and wall time, the chart's
// location in the rendering (confidence, accuracy).
nlohmann::json add_colour(MeasuredScene& scene, const Rendering& rendering, const nlohmann::json& characterize_run,
                          const nlohmann::json& chart_read_run);

// Every run the verification was given: the light ones through scene_from_runs (when any), the colour ones through
// add_colour (a characterize-camera run needs its chart-read, by its reference_run, among `runs`). Error(bad_parameter)
// for a run of another campaign, two of a kind, a chart-read without its characterize-camera or the reverse, or
// light and colour under different lamps.
// `colour` receives add_colour's account when colour was read.
MeasuredScene measured_scene_from_runs(const std::vector<nlohmann::json>& runs, const Rendering& rendering,
                                       const RunsSceneOptions& options = {}, nlohmann::json* colour = nullptr);

// The characterize-camera run's reference_run, or empty when the run is of another campaign.
std::string chart_read_of(const nlohmann::json& run);

}  // namespace colorlab::verify
