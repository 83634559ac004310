#pragma once
// A small lab on paper for the comparison's tests: a chart of smooth reflectances and a floor under one lamp,
// the truth as a spectral image (what a faithful renderer produces), and a measurement of it drawn with the
// noise each instrument has — the camera's frame noise, the lamp's drift within its bound, the LS-110's
// repeatability, the locator's and the floor homography's misregistration, the floor map's flat-field residual —
// plus the characterization and the black box fitted, on every draw, from their own noisy training photograph.
// The truth never comes from the code under test: it is the physics written here.
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "colorlab/verify/compare/verification.hpp"

namespace colorlab::verify::testing {

struct Sources {  // which noises the draw makes (and the engine is told of)
  bool frame_noise = true;
  bool drift = true;
  bool ls110 = true;
  bool misregistration = true;
  bool floor_map = true;
  bool characterization = true;  // false: §7.3/§7.4 mappings are exact (the true curves)
  // The chart-read's own reading noise (the Spectrolino's): each patch's spectrum read × (1 + gain) per patch and
  // × (1 + band) per band, both normal with these relative σ. The read spectra are what a renderer is given (measure's
  // `read`) and, with `read_is_reference`, what the characterization and the black box are fitted against, as the
  // colour half from runs does; false: fitted against the true spectra (a budget that lacks the reading noise).
  double read_gain_sd = 0;
  double read_band_sd = 0;
  bool read_is_reference = true;
};

// A Monte-Carlo renderer's own noise on a rendering: each pixel's spectrum × (1 + sd · n), n standard normal and the
// same in every band (one seed renders every band, as the Blender tests do: the sampled paths are the same in each),
// white or, `correlated`, the sum of a 2 × 2 block of white noise over 2 (unit variance; neighbours correlated 0.5,
// diagonals 0.25: a pixel filter two pixels wide). `per_band`: each band its own white noise instead (a renderer
// that samples each wavelength with its own paths), on the chart's rows only (what §7.4 reads; a million normal
// draws per rendering otherwise).
Rendering with_render_noise(const Rendering& r, std::mt19937_64& rng, double sd, bool correlated, bool per_band = false);

struct Defects {
  int patch = -1;  // this patch's reflectance scaled so it is ~3 ΔE00 off under the lamp
  double patch_factor = 1.0;
  double lamp_factor = 1.0;            // the whole rendering brighter
  std::string lamp_spd;                // the rendering lit by this CIE illuminant (same luminance) instead of the lamp
  double floor_factor = 1.0;           // the floor's reflectance in the region below
  int floor_rows = 3, floor_cols = 4;  // the region: rows [0, 3) × cols [0, 4)
};

class SyntheticLab {
 public:
  SyntheticLab();
  static constexpr int kPatches = 140;         // 14 × 10, as the SG
  static constexpr int kRows = 8, kCols = 10;  // the cabinet grid's left half

  // The spectral rendering a renderer that gets the physics right (or with the planted defects) produces, in
  // W·m⁻²·sr⁻¹·nm⁻¹: with the given scale 1 its luminance is in cd/m².
  // `reflectances` (patches × bands): the chart's patches rendered with these instead of the true ones.
  Rendering render(const Defects& d = {}, const Eigen::MatrixXd* reflectances = nullptr) const;
  // One draw of the whole measurement of the (faithful) scene; `read`, when given, gets the chart-read's spectra.
  MeasuredScene measure(std::mt19937_64& rng, const Sources& s, Eigen::MatrixXd* read = nullptr) const;
  // The reflectance factor that puts `patch` `de00` away from itself under the lamp.
  double factor_for_de00(int patch, double de00) const;
  // ΔE00 between the faithful and the defective rendering of each patch (the defect's true size, §7.3's way).
  std::vector<double> true_de00(const Defects& d) const;

  bool floor_region(int row, int col, const Defects& d) const { return row < d.floor_rows && col < d.floor_cols; }

 private:
  std::vector<double> wl_;   // 400..700 nm, 10 nm
  Eigen::MatrixXd refl_;     // patches × bands
  Eigen::RowVectorXd lamp_;  // the cabinet lamp (CIE F2 = the cabinet's CWF) × κ: radiance of the white
  Eigen::Matrix3Xd camera_;  // true sensitivities × band width, counts per radiance
  Eigen::Matrix3Xd cmf_;     // 683 · CIE 1931 × band width
  analysis::Xyz white_;      // XYZ (cd/m²) of the perfect diffuser
  std::vector<PixelRect> patch_regions_;
  std::vector<PixelRect> spot_regions_;  // kRows × kCols
  int width_ = 0, height_ = 0;

  double floor_field(double x, double y) const;  // relative illumination of the floor at a pixel centre
  double floor_mean(const PixelRect& g, double dx, double dy) const;
  Eigen::RowVectorXd lamp_named(const std::string& name) const;
};

}  // namespace colorlab::verify::testing
