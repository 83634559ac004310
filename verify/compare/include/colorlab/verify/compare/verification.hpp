#pragma once
// The rendering beside the measurement (issue 23, docs/verify.md "Comparing and the uncertainty"): the measured
// scene as the comparisons need it (filled from the runs by measured_scene_from_runs, or by a test from its own
// simulation), the comparisons of §7.3, §7.4 and the light, and their verdicts.
#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/verify/rendering.hpp"

namespace colorlab::verify {

using Rgb3 = std::array<double, 3>;

// Pixels [x, x + w) × [y, y + h) of the rendering.
struct PixelRect {
  int x = 0, y = 0, w = 0, h = 0;
};

// ---- the measurement ------------------------------------------------------------------------------------------

// One chart patch as the raw photograph gave it.
struct PatchMeasurement {
  std::string id;
  Rgb3 camera{};               // robust patch value, counts above black (linear), the characterization's input
  Rgb3 frame_noise{};          // standard error of `camera` after averaging the frames, per channel
  PixelRect rendering_region;  // where the chart locator found the patch in the rendering
};

// §7.3: the characterize-camera run's selected characterization of the raw.
struct Characterization {
  std::string name;  // e.g. "adapted_mapping/raw poly 10"
  // Camera values -> XYZ of the scene as lit by the cabinet's lamp, the lamp's perfect diffuser at Y = 100.
  std::function<analysis::Xyz(const Rgb3&)> to_xyz;
  analysis::Xyz white{};  // XYZ of that perfect diffuser (Y = 100): the Lab white of both sides
  // Its cross-validated errors, where in colour space they were made: each training patch's reference L*a*b* and
  // its held-out prediction's error (predicted − reference: ΔL*, Δa*, Δb*). As vectors, not ΔE00 values: a
  // mapping's error has a direction (mostly lightness, or mostly along one hue), and a band drawn as a sphere
  // around it covers too little along that direction and too much across it.
  std::vector<analysis::Lab> cv_lab;
  std::vector<Rgb3> cv_error;
};

// §7.4: the black box — the camera's fitted spectral sensitivities.
struct BlackBox {
  std::vector<double> wavelengths_nm;
  std::array<std::vector<double>, 3> sensitivity;  // counts per unit spectral radiance and nm (any common constant)
  // Cross-validated residual (predicted − measured counts) of each training patch, with its counts: the mapping's
  // error in that region of the camera's space (Table 13, held out). These held-out errors already contain the
  // training photograph's frame noise; the comparison counts only what exceeds the photograph's own frame noise
  // as the mapping's (docs/verify.md), so the noise is not counted twice.
  std::vector<Rgb3> cv_camera;
  std::vector<Rgb3> cv_residual;
};

struct SpotMeasurement {  // one LS-110 spot of the cabinet-grid run
  int row = 0, col = 0;
  double luminance_cd_m2 = 0;  // mean of the readings
  double reading_sd = 0;       // one reading's standard deviation (the LS-110's repeatability), cd/m²
  int readings = 1;
  PixelRect rendering_region;  // the spot (meter's measuring field) in the rendering
};

struct FloorCell {  // one spot of the floor-luminance map (the camera as an imaging luminance meter)
  int row = 0, col = 0;
  double luminance_cd_m2 = 0;
  double relative_sd = 0;  // the flat field's calibration residual and the photograph's noise, combined, relative
  PixelRect rendering_region;
};

struct MeasuredScene {
  std::string lamp;               // e.g. "CWF"
  std::vector<std::string> runs;  // the run ids it came from
  std::vector<PatchMeasurement> patches;
  std::optional<Characterization> characterization;
  std::optional<BlackBox> black_box;
  std::optional<double> white_luminance_cd_m2;  // the lamp's perfect diffuser at the chart (LS-110), for a given scale
  double white_relative_sd = 0;                 // its standard uncertainty, relative
  std::vector<SpotMeasurement> spots;
  std::vector<FloorCell> floor;
  int floor_rows = 0, floor_cols = 0;
  double lamp_drift_bound = 0;     // relative: how far the lamp may have moved over the run (a bound, not a σ)
  double locator_accuracy_px = 0;  // the chart locator's stated accuracy, one σ, rendering pixels
  double floor_accuracy_px = 0;    // the floor homography's, one σ, rendering pixels
};

// ---- the comparison -------------------------------------------------------------------------------------------

struct CompareOptions {
  // Renderer units -> cd/m² (luminance from Y). Absent: one factor fitted per comparison kind (median ratio), and
  // the result says so — a fitted factor cannot see a lamp that is uniformly too bright.
  std::optional<double> scale;
  int cv_neighbours = 12;  // training patches that stand for a patch's region of colour space
  double k = 2;            // coverage factor, read as its one-dimensional coverage probability
  // Expanded uncertainties above these mean the measurement cannot tell a renderer error of that size there.
  double cannot_tell_de00 = 2.0;
  double cannot_tell_relative = 0.02;
  // The rendering's own noise (a Monte-Carlo renderer's region mean is an estimate too), estimated from the
  // rendering: its per-pixel spread in each region, pooled over the `noise_neighbours` (≥ 1) nearest regions of the
  // same kind, regions whose residuals their neighbours do not share left out, with the noise's spatial correlation
  // (docs/verify.md). Off only for a renderer that states it is exact (CLI --no-rendering-noise, the API's
  // "rendering_noise": false); both are kept in a stored verification's params.
  bool rendering_noise = true;
  int noise_neighbours = 8;
};

// Throws Error(bad_parameter) naming the option for options no comparison can be made with: a scale that is not a
// positive number, k ≤ 0, noise_neighbours < 1 (whether or not the rendering's noise is on: a request that says both
// is not guessed at). compare() calls it; the CLI and the daemon call it on what they were given.
void check_options(const CompareOptions& options);

enum class Verdict {
  agrees,
  differs
};
std::string_view to_string(Verdict v);

struct Comparison {
  std::string kind;                        // "colour_7_3", "colour_7_4", "light_spot", "light_floor"
  std::string where;                       // patch id, or "r<row>c<col>"
  std::vector<double> rendered, measured;  // L*a*b*, raw counts, or cd/m²
  double difference = 0;                   // ΔE00 (7.3); |Δ| / |measured| (7.4); rendered / measured − 1 (light)
  double expanded = 0;                     // the expanded uncertainty along the difference, same unit
  double mahalanobis = 0, threshold = 0;
  Verdict verdict = Verdict::agrees;
  bool cannot_tell = false;
  // The rendering-noise screen judged this region's residuals an outlier against its neighbours' (a texture, an
  // edge, a firefly): its `rendering noise` is its own spread alone, and it was kept out of the others' pools.
  bool noise_left_out = false;
  std::vector<std::pair<std::string, double>> budget;  // standard uncertainty per source along the difference
};

struct ScaleUsed {
  std::string kind;
  std::string how;  // "given" or "fitted"
  double factor = 1;
};

struct Verification {
  std::vector<Comparison> comparisons;
  std::vector<ScaleUsed> scales;
  std::vector<std::vector<double>> floor_ratio;  // floor_rows × floor_cols: rendered / measured − 1 (NaN: no cell)
  bool differs() const;
  nlohmann::json to_json() const;  // with the summary
  nlohmann::json summary() const;
};

// Runs every comparison the scene and the rendering allow: §7.3 needs a characterization and patches, §7.4 a
// spectral rendering and a black box, the light spots and/or floor cells. Throws Error(bad_parameter) when none
// applies, Error(bad_data) for a region outside the rendering or a rendering without pixels.
Verification compare(const Rendering& rendering, const MeasuredScene& scene, const CompareOptions& options = {});

}  // namespace colorlab::verify
