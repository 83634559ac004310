#pragma once
// Image formation of the simulated camera: the chart in the cabinet, seen through spectral sensitivities
// (Canon EOS 20D curves when the shared data set is present, else a parametric default), turned into
// electrons by aperture, shutter and ISO, and into a 12-bit RGGB frame with shot, read and dark noise,
// PRNU and fixed-pattern offsets, hot/dead pixels and sensor dust (fixed per camera seed), vignetting,
// black level and clipping.
//
// The noiseless image is computed once per (settings, scene state) and cached; a frame only adds noise,
// seeded by (camera seed, frame_index), so any frame can be reproduced bit-exactly.
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "colorlab/sim/camera/raw_frame.hpp"
#include "colorlab/sim/scene.hpp"

namespace colorlab::sim::camera {

// Where the chart sits in front of the camera (issue 14). Unset in CameraConfig: the chart square to the sensor,
// centred, filling chart_height_fraction of the frame height, no lens distortion (the original behaviour).
struct ChartPose {
  double rotation_deg = 0;  // in the image plane, clockwise
  // Positive tilt: the chart's top edge (row 1) leans away from the camera, as a chart on the cabinet floor (row 1
  // at the back) leans for a camera at the open front. Positive swing: its right edge leans away.
  double tilt_deg = 0;        // about the chart's horizontal axis
  double swing_deg = 0;       // about its vertical axis
  double distance_mm = 1200;  // camera to chart centre; the focal length keeps the chart at chart_height_fraction
  // chart centre offset as a fraction of the frame width / height
  double shift_x = 0, shift_y = 0;
  double k1 = 0, k2 = 0;  // radial lens distortion (OpenCV's model, coordinates normalised by the focal length)
  // The lens's principal point off the frame's centre (px, +x right, +y down) and fy / fx (square pixels: 1). A real
  // lens has both (a few px, ~0.1 %); opt-in, so no seeded pose's photograph moves (docs/verify.md, the simulated lens).
  double principal_dx_px = 0, principal_dy_px = 0;
  double fy_over_fx = 1;
};
// A plausible bench pose for a seed: a few degrees of rotation and tilt, some shift, mild barrel distortion.
ChartPose random_chart_pose(std::uint64_t seed);

// The pinhole camera of a posed chart, in OpenCV's conventions (pixel centres at integers).
struct LensIntrinsics {
  double fx = 0, fy = 0, cx = 0, cy = 0, k1 = 0, k2 = 0;
};

// Where an operator puts the chart in front of the camera (the lens-calibration campaign's poses; docs/simulator.md,
// "place_chart"): its attitude and where it sits in the frame. The lens is the camera's, so the distance is whatever
// makes the chart `fill` that share of the frame's height.
struct ChartPlacement {
  double rotation_deg = 0, tilt_deg = 0, swing_deg = 0;  // as ChartPose's
  double fill = 0.5;                                     // of the frame height the chart's height fills square-on
  double shift_x = 0, shift_y = 0;                       // chart centre offset as a fraction of the frame width / height
};

struct CameraConfig {
  int width = 3504;                   // even
  int height = 2336;                  // even
  std::optional<std::uint64_t> seed;  // default: the scene's "camera" stream
  // CSV wavelength_nm,R,G,B. Unset: the shared set's Canon 20D curves when present, else parametric.
  std::optional<std::filesystem::path> sensitivity_file;
  bool force_parametric_sensitivities = false;
  double chart_height_fraction = 0.8;  // of the frame height the chart fills
  std::optional<ChartPose> pose;       // unset: square to the sensor, centred, no distortion
  // The floor view's radial distortion (OpenCV's k1, k2 about the frame's centre). Default none: the floor
  // photographs, and the campaigns' figures read from them, stay as they were; a test of a lens-aware placement
  // turns it on.
  double floor_k1 = 0, floor_k2 = 0;
  // Sensor (EOS-20D-like): DN per electron at ISO 100, full well, read noise, dark current.
  double gain_dn_per_e_iso100 = 0.09;
  double read_noise_e = 9.0;
  double adc_noise_dn = 0.8;
  double dark_current_e_per_s = 0.5;
  double prnu_sigma = 0.006;            // pixel gain non-uniformity (relative)
  double dsnu_sigma_dn = 0.5;           // pixel offset non-uniformity
  double column_offset_sigma_dn = 0.3;  // column fixed-pattern
  double hot_pixel_fraction = 2e-5;
  double dead_pixel_fraction = 1e-5;
  int dust_specks = 6;  // dust shadows, each on a patch
  int threads = 2;      // for rendering frames
  // Electrons per (cd·s·m⁻²) of green-channel exposure L·t/N² (sets the overall brightness).
  double electrons_per_exposure = 15500.0;
};

struct PatchRegion {
  int x = 0, y = 0, width = 0, height = 0;  // pixels; the whole patch square
};

struct PixelDefect {
  int x = 0, y = 0;
  enum class Kind {
    hot,
    dead
  } kind = Kind::hot;
};

struct DustSpeck {
  double x = 0, y = 0, radius = 0;  // pixels
  double transmission = 1;          // < 1: darker
  int patch = -1;
};

class CameraModel {
 public:
  // What the camera photographs: the chart in the cabinet (the default), or the empty cabinet floor — the chart
  // taken out and the camera aimed at the whole floor from the cabinet's open front, as an imaging luminance meter
  // sees it (docs/simulator.md, "camera_view"). The floor is the scene's one luminance field, the one the LS-110
  // reads, seen through this view's perspective, its lens's cos⁴ fall-off and the camera's own vignetting and noise.
  enum class View {
    chart,
    floor
  };

  CameraModel(std::shared_ptr<const Scene> scene, CameraConfig config = {});
  ~CameraModel();
  CameraModel(const CameraModel&) = delete;
  CameraModel& operator=(const CameraModel&) = delete;

  int width() const;
  int height() const;
  std::uint64_t seed() const;
  const CameraConfig& config() const;

  // Renders frame `frame_index` under the scene's current lamps, dimmer, warm-up and drift. Thread-safe.
  // Throws Error(bad_parameter) for non-positive f-number/shutter or ISO outside 50..3200.
  RawFrame render(const CameraSettings& settings, std::uint64_t frame_index) const;
  // Same, reusing `out`'s buffer.
  void render_into(RawFrame& out, const CameraSettings& settings, std::uint64_t frame_index) const;

  // Pixel rectangle of patch 0..139 (Chart order: A1, A2, ..., N10). With a pose: the largest axis-aligned
  // rectangle centred on the patch inside its (tilted) image.
  PatchRegion patch_region(int patch_index) const;
  // Ground truth of the geometry, pixel centres at integers (OpenCV's convention): a patch's centre, and the outer
  // corners of the patch grid (A1's, N1's, N10's, A10's outer corner) in that order.
  std::array<double, 2> patch_centre_px(int patch_index) const;
  std::array<std::array<double, 2>, 4> patch_grid_corners_px() const;
  // The lens of a posed chart (zero distortion and a nominal focal length without a pose).
  LensIntrinsics lens() const;
  // Ground truth: noiseless mean counts (including the black level) of R, G, B pixels over the patch region,
  // without PRNU, dust and defective pixels, for the scene's current state.
  std::array<double, 3> ground_truth(int patch_index, const CameraSettings& settings) const;
  std::vector<std::array<double, 3>> ground_truth(const CameraSettings& settings) const;

  // Fixed per camera seed.
  const std::vector<PixelDefect>& defects() const;
  const std::vector<DustSpeck>& dust() const;

  // The operator places the chart (thread-safe; frames rendered from now on show it there), seen through this camera's
  // lens: its focal length and distortion stay as configured, which is what makes photographs at several placements
  // a lens calibration's. nullopt: back where the configuration put it (bit-exact: every figure made at the
  // configured pose is unchanged). Dust stays where it is on the sensor. Throws Error(bad_parameter) for a placement
  // the geometry refuses (fill outside (0.1, 1], a shift beyond ±0.5, tilt or swing of 70° or more).
  void place_chart(const std::optional<ChartPlacement>& placement);
  std::optional<ChartPlacement> chart_placement() const;  // nullopt: where the configuration put it

  // Aims the camera (thread-safe; frames rendered from now on show the new view).
  void set_view(View view);
  View view() const;
  // The floor view's geometry (whatever the current view), pixel centres at integers: the image position of a
  // floor point (mm, the scene's coordinates), and of the floor's corners — front-left, front-right, back-right,
  // back-left — which is what a bench measures on its own photograph to map the floor.
  std::array<double, 2> floor_point_px(double x_mm, double y_mm) const;
  std::array<std::array<double, 2>, 4> floor_corners_px() const;
  // Where the same camera without its distortion (a pinhole of the same intrinsics and pose: a renderer's view of
  // it) sees a floor point, pixel centres at integers; and the floor view's lens, OpenCV's model.
  std::array<double, 2> floor_point_pinhole_px(double x_mm, double y_mm) const;
  LensIntrinsics floor_lens() const;
  // The relative illumination the optics give a pixel in a view (1 = none lost): the lens's vignetting at this
  // f-number, times the cos⁴ fall-off in the floor view. Pixel centres at integers.
  double relative_illumination(double x_px, double y_px, double f_number, View view) const;

  // Relative spectral sensitivities (R, G, B) on 380–730 nm / 5 nm, and their source ("file path" or "parametric").
  const std::array<Spectrum, 3>& sensitivities() const;
  const std::string& sensitivity_source() const;

  // XYZ (D65-adapted, Y=1 white) → camera RGB (white-balanced to G=1 for D65) least-squares fit over the chart:
  // what a DNG's ColorMatrix1 carries. Row-major 3×3.
  std::array<double, 9> xyz_to_camera_d65() const;
  // Camera RGB of a perfect white under the current lamps, normalised to G = 1 (a DNG's AsShotNeutral).
  std::array<double, 3> as_shot_neutral() const;

  // Temporal noise σ (DN) of a pixel with this mean signal above black (electrons → DN), for tests.
  double temporal_sigma_dn(double signal_dn, const CameraSettings& settings) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace colorlab::sim::camera
