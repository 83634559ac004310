#pragma once
// Chapter 7 (c): polynomial RGB → L*a*b* mappings with honest (cross-validated) errors and model selection.
//
//   ChartData train = ...;                               // camera RGB + reference XYZ/L*a*b* per patch
//   auto model = fit("rootpoly:2", train);                // least squares by column-pivoting QR, never normal equations
//   Eigen::MatrixXd lab = model.apply(rgb);               // n × 3 L*a*b*
//   ErrorStats cv = cross_validate(term_set_by_name("poly:10"), train, {}, CvSpec::loo());
//   Selection s = select_model(all_term_sets(), {FitTarget::xyz_then_lab}, train);  // smallest within tolerance
#include <Eigen/Dense>
#include <string>
#include <vector>

#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/analysis/polynomial_terms.hpp"
#include "colorlab/analysis/statistics.hpp"

namespace colorlab::analysis {

// Camera values of a chart with reference colours, one row per patch.
struct ChartData {
  std::vector<std::string> ids;
  Eigen::MatrixXd rgb;  // n × 3 camera values (any scale; linear or encoded)
  Eigen::MatrixXd xyz;  // n × 3, Y = 100 for the perfect reflector
  Eigen::MatrixXd lab;  // n × 3, against `white`
  Xyz white = kIccD50White;

  std::size_t size() const { return ids.size(); }
  void check() const;  // throws Error(bad_data) for mismatched counts, NaN, empty data
  ChartData subset(const std::vector<std::size_t>& rows) const;
};

enum class FitTarget {
  lab_direct,    // regress L*a*b* itself (the dissertation)
  xyz_then_lab,  // regress XYZ, convert with the white
  // Regress XYZ with each patch weighted by (Y/Yn)^(-2/3), the slope of L* = 116·(Y/Yn)^(1/3) − 16: least squares
  // in XYZ then approximates least squares in L*a*b*, so dark patches are not neglected.
  xyz_lightness_weighted,
};
const char* to_string(FitTarget t);

// How a spline's λ search solves its 41 systems (scattered_data.hpp): one generalised eigendecomposition reused for
// every λ, or an LU per λ — the original path, kept as the reference the faster one is checked against.
enum class SmoothingSearch {
  eigen,
  direct
};

struct FitOptions {
  FitTarget target = FitTarget::xyz_then_lab;
  double ridge = 0;        // Tikhonov weight on the coefficients of the 0..1-scaled terms (0 = plain least squares)
  double input_scale = 0;  // RGB divisor; 0 = largest training value, so inputs lie in 0..1
  // splines only
  SmoothingSearch spline_search = SmoothingSearch::eigen;
};

class PolynomialModel {
 public:
  PolynomialModel(TermSet terms, FitTarget target, Eigen::MatrixXd coefficients, double input_scale, Xyz white);
  Eigen::MatrixXd apply(const Eigen::MatrixXd& rgb) const;           // → L*a*b* (n × 3)
  Eigen::MatrixXd predict_target(const Eigen::MatrixXd& rgb) const;  // → XYZ or L*a*b*, as fitted
  const TermSet& terms() const { return terms_; }
  FitTarget target() const { return target_; }
  const Eigen::MatrixXd& coefficients() const { return coefficients_; }  // m × 3, for RGB / input_scale
  double input_scale() const { return input_scale_; }

 private:
  TermSet terms_;
  FitTarget target_;
  Eigen::MatrixXd coefficients_;
  double input_scale_;
  Xyz white_;
};

// Throws Error(bad_data) for a rank-deficient design (naming method, patches, terms and rank).
PolynomialModel fit(const TermSet& terms, const ChartData& train, const FitOptions& options = {});
PolynomialModel fit(const std::string& method, const ChartData& train, const FitOptions& options = {});

struct ErrorStats {
  std::vector<double> de76, de00;  // per patch (infinity where a held-out patch could not be predicted)
  Summary s76, s00;                // min/max/median/mean/stdev; mean = inf if any patch is inf
};
ErrorStats evaluate(const Eigen::MatrixXd& predicted_lab, const Eigen::MatrixXd& reference_lab);

struct CvSpec {
  enum class Kind {
    none,
    leave_one_out,
    k_fold
  } kind = Kind::leave_one_out;
  int folds = 10;
  unsigned seed = 1;
  static CvSpec loo() { return {}; }
  static CvSpec k_fold(int k, unsigned seed = 1) { return {Kind::k_fold, k, seed}; }
  static CvSpec parse(const std::string& text);  // "loo", "k5", "none"
  std::string name() const;
};

// Errors on patches each predicted by a model that did not see them. LOO uses the exact leverage identity.
ErrorStats cross_validate(const TermSet& terms, const ChartData& data, const FitOptions& options, const CvSpec& cv);

struct FitReport {
  std::string method;
  std::size_t terms = 0;
  // Effective number of parameters per channel: the term count for a polynomial, tr(H) for a smoothing spline.
  // Selection compares models by this, so a spline with 140 centres but heavy smoothing counts as small.
  double parameters = 0;
  FitTarget target = FitTarget::xyz_then_lab;
  ErrorStats training, cv;
  std::string cv_name;
  bool rank_deficient = false;
};
FitReport fit_report(const TermSet& terms, const ChartData& data, const FitOptions& options, const CvSpec& cv);

struct SelectionOptions {
  // The chosen model has the fewest terms among those whose mean cross-validated ΔE00 is within this much of the
  // best one's (absolute, ΔE00 units).
  double tolerance_de00 = 0.1;
};
struct Selection {
  std::vector<FitReport> candidates;
  std::size_t best = 0;    // lowest mean CV ΔE00
  std::size_t chosen = 0;  // smallest within tolerance
  double tolerance = 0;
};
Selection select_model(const std::vector<TermSet>& sets, const std::vector<FitTarget>& targets, const ChartData& data,
                       const FitOptions& options = {}, const CvSpec& cv = CvSpec::loo(),
                       const SelectionOptions& selection = {});

// The rule shared by every selection: best = lowest mean CV ΔE00; chosen = fewest `parameters` among candidates within
// the tolerance of the best (ties to the lower error). Throws Error(bad_data) if nothing could be cross-validated.
void choose_smallest_within_tolerance(Selection& selection, const SelectionOptions& options, std::size_t patches);

// Square roots of the least-squares row weights for a target (ones, or the slope of L* for xyz_lightness_weighted).
Eigen::VectorXd target_weights(const ChartData& data, FitTarget target);

// Row-wise conversions for n × 3 matrices.
Eigen::MatrixXd xyz_rows_to_lab(const Eigen::MatrixXd& xyz, const Xyz& white);

}  // namespace colorlab::analysis
