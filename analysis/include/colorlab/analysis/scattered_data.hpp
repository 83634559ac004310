#pragma once
// Scattered-data characterization: a polyharmonic (r³) radial-basis spline over a polynomial base.
//
// Why: polynomials are global — every coefficient answers to every patch, so a 140-patch SG fit that is good on
// average can still miss a saturated CC24 patch by ~2 ΔE00 (colprof's cLUT reaches ~1.5). A spline keeps the
// polynomial base for the global trend (the linear camera→XYZ matrix is exactly representable, which is what
// extrapolates sensibly) and adds local corrections whose smoothness is chosen by cross-validation.
//
//   f(rgb) = Σ_j c_j · ‖u − u_j‖³ + P(rgb) · d,  u = ∛(rgb / scale) (distances roughly like L*a*b*'s cube root)
//   P = base term set ∪ {1, u_r, u_g, u_b}   (r³ is conditionally positive definite of order 2: needs 1 and u)
//   minimise Σ w_i² ‖y_i − f(rgb_i)‖² + λ·cᵀKc   (w = FitTarget weights, y = XYZ or L*a*b*; u lies in the unit cube)
//
// The fit is a linear smoother (fitted = H y), so leave-one-out errors are exact from e_i / (1 − h_ii), and tr(H) is
// its effective number of parameters per channel — the size that model selection compares with a polynomial's term
// count. λ follows the same rule as selection, "the smallest model within tolerance of the best": the smoothest λ
// whose LOO mean ΔE00 is within one standard error of the lowest. Why not the lowest: LOO inside the training cloud
// rewards following it closely; one standard error more smoothing costs nothing measurable there and halves the
// worst error with 1 % RAW noise and on patches outside the training gamut (docs/ACCURACY.md §4).
#include <Eigen/Dense>
#include <optional>
#include <string>

#include "colorlab/analysis/regression.hpp"

namespace colorlab::analysis {

struct SplineOptions {
  std::string base = "ccm";  // polynomial term set under the spline ("ccm", "rootpoly:2", …)
  FitTarget target = FitTarget::xyz_then_lab;
  double input_scale = 0;           // as FitOptions::input_scale
  std::optional<double> smoothing;  // λ; unset = chosen by leave-one-out ΔE00
  double smoothing_min = 1e-8, smoothing_max = 1e2;
  int smoothing_steps = 41;
  // λ is the smoothest grid value whose LOO mean ΔE00 is within this of the best λ's; unset = one standard error of
  // the best λ's mean (the one-standard-error rule of Breiman et al. 1984).
  std::optional<double> smoothing_tolerance;        // log-spaced grid
  SmoothingSearch search = SmoothingSearch::eigen;  // same λ and fit either way, to rounding; eigen is ~10× cheaper
  // false, at a given λ: the coefficients only, without the hat matrix (an n-column solve, most of a refit's time);
  // effective_parameters() is then NaN. For refits whose model alone is used (the across-lamps band's draws).
  // spline_report always solves for it: its LOO errors are the hat's leverages.
  bool hat_matrix = true;
};

class SplineModel {
 public:
  Eigen::MatrixXd apply(const Eigen::MatrixXd& rgb) const;           // → L*a*b* (n × 3)
  Eigen::MatrixXd predict_target(const Eigen::MatrixXd& rgb) const;  // → XYZ or L*a*b*, as fitted
  const std::string& method() const { return method_; }
  FitTarget target() const { return target_; }
  double smoothing() const { return smoothing_; }                                    // λ used
  double effective_parameters() const { return dof_; }                               // tr(H)
  std::size_t base_terms() const { return static_cast<std::size_t>(poly_.rows()); }  // incl. the added 1 and ∛rgb
  double input_scale() const { return input_scale_; }
  std::string describe() const;  // "r³ spline over ccm (λ …, … effective parameters)"

 private:
  friend struct SplineFitter;  // scattered_data.cpp: the fit, with the smoother's leverages for the report
  std::string method_;
  TermSet base_;
  FitTarget target_ = FitTarget::xyz_then_lab;
  double input_scale_ = 1, smoothing_ = 0, dof_ = 0;
  Xyz white_ = kIccD50White;
  Eigen::MatrixXd centres_;  // n × 3 cube-root coordinates of the training patches
  Eigen::MatrixXd kernel_;   // n × 3 kernel coefficients c
  Eigen::MatrixXd poly_;     // m × 3 polynomial coefficients d
};

// "rbf:<term set>" (e.g. "rbf:ccm", "rbf:rootpoly:2"); is_spline_method tells the CLI and selection apart.
bool is_spline_method(const std::string& method);
std::string spline_method(const std::string& base);
SplineOptions spline_options(const std::string& method, const FitOptions& options);

// Throws Error(bad_data) when the base plus {1, u} is rank-deficient on the training patches.
SplineModel fit_spline(const ChartData& train, const SplineOptions& options = {});

// Training and cross-validated errors. LOO: exact, at the λ chosen on all patches (as a polynomial's term set is
// chosen on the same LOO). k-fold: nested — each fold chooses its own λ by LOO on its training patches.
FitReport spline_report(const ChartData& data, const SplineOptions& options, const CvSpec& cv);

// Each patch's held-out prediction of the fitted target (XYZ or L*a*b*, per options.target), n × 3, at the given λ
// (options.smoothing, required) and input scale (0: the data's largest value, as spline_report's LOO): the exact
// leave-one-out of the linear smoother, y_i − e_i / (1 − h_ii), so per-patch error vectors cost one solve, not n
// fits (issue 23's verification). NaN rows where h_ii ≈ 1.
Eigen::MatrixXd spline_loo_targets(const ChartData& data, const SplineOptions& options);

}  // namespace colorlab::analysis
