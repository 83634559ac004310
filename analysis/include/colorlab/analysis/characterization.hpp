#pragma once
// One entry point for every characterization family — polynomial term sets and splines over them — so that model
// selection can choose among all of them by the same rule and callers can apply whatever was chosen.
//
//   Selection s = select_method(all_methods(), {FitTarget::xyz_then_lab}, train, {}, CvSpec::loo());
//   Characterization m = fit_method(s.candidates[s.chosen].method, train, options_for(s.candidates[s.chosen]));
//   Eigen::MatrixXd lab = m.apply(rgb);
#include <string>
#include <variant>
#include <vector>

#include "colorlab/analysis/regression.hpp"
#include "colorlab/analysis/scattered_data.hpp"

namespace colorlab::analysis {

class Characterization {
 public:
  explicit Characterization(PolynomialModel m) : model_(std::move(m)) {}
  explicit Characterization(SplineModel m) : model_(std::move(m)) {}
  Eigen::MatrixXd apply(const Eigen::MatrixXd& rgb) const;           // → L*a*b*
  Eigen::MatrixXd predict_target(const Eigen::MatrixXd& rgb) const;  // → XYZ or L*a*b*, as fitted
  std::string method() const;
  std::string describe() const;  // the term labels, or the spline's base, λ and effective parameters
  double input_scale() const;
  const SplineModel* spline() const { return std::get_if<SplineModel>(&model_); }

 private:
  std::variant<PolynomialModel, SplineModel> model_;
};

// Any term set name ("poly:10", "rootpoly:2", "ccm", …) or "rbf:<term set>".
Characterization fit_method(const std::string& method, const ChartData& train, const FitOptions& options = {});
FitReport report_method(const std::string& method, const ChartData& data, const FitOptions& options, const CvSpec& cv);

// The spline candidates selection tries (the spline over the 3×3 matrix; see characterization.cpp for why only it).
std::vector<std::string> spline_methods();
// Every polynomial term set, then the splines.
std::vector<std::string> all_methods();

// Every method × target, cross-validated, chosen by choose_smallest_within_tolerance.
Selection select_method(const std::vector<std::string>& methods, const std::vector<FitTarget>& targets,
                        const ChartData& data, const FitOptions& options = {}, const CvSpec& cv = CvSpec::loo(),
                        const SelectionOptions& selection = {});

}  // namespace colorlab::analysis
