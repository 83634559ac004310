#pragma once
// Spectra to tristimulus values and the CIE colour spaces built on them (CIE 15:2004).
#include <vector>

#include "colorlab/analysis/spectral.hpp"
#include "colorlab/analysis/standard_data.hpp"

namespace colorlab::analysis {

struct Xyz {
  double X = 0, Y = 0, Z = 0;
};
struct XyY {
  double x = 0, y = 0, Y = 0;
};
struct Lab {
  double L = 0, a = 0, b = 0;
};
struct Luv {
  double L = 0, u = 0, v = 0;
};

inline constexpr Xyz kIccD50White{96.42, 100.0, 82.49};  // what ICC (and ArgyllCMS) use as D50

struct IntegrationOptions {
  // Lamps with line spectra (F2, F11) need a fine grid: subsampling them to 10 nm moves the white point.
  double step_nm = 1.0;
  Interpolation reflectance = Interpolation::sprague;  // CIE 167:2005; spline where the grid is not uniform
  Interpolation illuminant = Interpolation::linear;
  Interpolation observer = Interpolation::cubic_spline;
  // CIE 15:2004 §7.2.2.1: outside the measured range a reflectance equals its nearest measured value, so the
  // integral runs over the whole range the illuminant and observer share (360–830 nm for colord's tables).
  bool extrapolate_reflectance = true;
  // Hold the lamp's end values out to the observer's range (ArgyllCMS does this); CIE 15 integrates only where the
  // lamp is tabulated.
  bool extrapolate_illuminant = false;
};

// Precomputes weights for one illuminant, observer and reflectance grid so that XYZ = W · reflectance, integrated on
// a fine common grid over the range all three cover. Y of the perfect reflector is 100.
class ReflectanceIntegrator {
 public:
  ReflectanceIntegrator(const SpectralSet& illuminant, const SpectralSet& observer,
                        const std::vector<double>& reflectance_grid, IntegrationOptions options = {});
  Xyz white() const { return white_; }
  Xyz xyz(const Eigen::Ref<const Eigen::RowVectorXd>& reflectance) const;
  // Validates the set (NaN, negative) and its grid against the one given at construction.
  std::vector<Xyz> xyz(const SpectralSet& reflectances) const;
  const Eigen::MatrixXd& weights() const { return weights_; }  // 3 × bands

 private:
  friend class IntegratorGrids;
  ReflectanceIntegrator() = default;
  std::vector<double> grid_;
  Eigen::MatrixXd weights_;
  Xyz white_;
};

// What a ReflectanceIntegrator resamples, for every illuminant tabulated on one grid: kept where many spectra on the
// same wavelengths are integrated (each posterior draw of a nominal lamp, relighting.hpp), so that each integrator
// costs two small products instead of three resampling matrices. integrator(s) is ReflectanceIntegrator(s, observer,
// reflectance_grid, options), the same arithmetic.
class IntegratorGrids {
 public:
  IntegratorGrids(const std::vector<double>& illuminant_grid, const SpectralSet& observer, const std::vector<double>& reflectance_grid,
                  IntegrationOptions options = {});
  // illuminant: one spectrum on illuminant_grid (Error(bad_data) otherwise).
  ReflectanceIntegrator integrator(const SpectralSet& illuminant) const;

 private:
  std::vector<double> illuminant_grid_, reflectance_grid_;
  double step_nm_ = 1;
  Eigen::MatrixXd illuminant_;   // fine × illuminant bands
  Eigen::MatrixXd cmf_;          // 3 × fine: the observer on the fine grid
  Eigen::MatrixXd reflectance_;  // fine × reflectance bands
};

// Convenience: reflectances under a named/loaded illuminant.
std::vector<Xyz> reflectance_to_xyz(const SpectralSet& reflectances, const SpectralSet& illuminant, Observer observer,
                                    IntegrationOptions options = {});
// Emission spectra (e.g. radiance in W·sr⁻¹·m⁻²·nm⁻¹) integrated on their own grid; k = 683 gives cd/m² for Y.
// With k = 0 the result is normalised to Y = 100.
std::vector<Xyz> emission_to_xyz(const SpectralSet& spectra, Observer observer, double k = 683.0);
// White point (Y = 100) of an illuminant spectrum.
Xyz illuminant_white(const SpectralSet& illuminant, Observer observer);

XyY xyz_to_xyy(const Xyz& c);
Xyz xyy_to_xyz(const XyY& c);
// Includes the linear branch below (6/29)³ of CIE 15 (§3.1 of the dissertation).
Lab xyz_to_lab(const Xyz& c, const Xyz& white);
Xyz lab_to_xyz(const Lab& c, const Xyz& white);
Luv xyz_to_luv(const Xyz& c, const Xyz& white);

// Bradford chromatic adaptation from one white to another (linear, as in ICC v4 Annex E).
Xyz bradford_adapt(const Xyz& c, const Xyz& from_white, const Xyz& to_white);

}  // namespace colorlab::analysis
