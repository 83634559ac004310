#include "colorlab/analysis/characterization.hpp"

#include "colorlab/core/error.hpp"

namespace colorlab::analysis {

Eigen::MatrixXd Characterization::apply(const Eigen::MatrixXd& rgb) const {
  return std::visit([&](const auto& m) { return m.apply(rgb); }, model_);
}

Eigen::MatrixXd Characterization::predict_target(const Eigen::MatrixXd& rgb) const {
  return std::visit([&](const auto& m) { return m.predict_target(rgb); }, model_);
}

std::string Characterization::method() const {
  if (const auto* s = spline()) return s->method();
  return std::get<PolynomialModel>(model_).terms().name;
}

std::string Characterization::describe() const {
  if (const auto* s = spline()) return s->describe();
  return std::get<PolynomialModel>(model_).terms().describe();
}

double Characterization::input_scale() const {
  return std::visit([](const auto& m) { return m.input_scale(); }, model_);
}

Characterization fit_method(const std::string& method, const ChartData& train, const FitOptions& o) {
  if (is_spline_method(method)) return Characterization(fit_spline(train, spline_options(method, o)));
  return Characterization(fit(method, train, o));
}

FitReport report_method(const std::string& method, const ChartData& data, const FitOptions& o, const CvSpec& cv) {
  if (is_spline_method(method)) return spline_report(data, spline_options(method, o), cv);
  return fit_report(term_set_by_name(method), data, o, cv);
}

// Only the matrix base: over rootpoly:2 the spline is as good inside the training gamut, but the square-root terms make
// it extrapolate badly (the 20 most saturated SG patches held out: max 9.7 ΔE00 against 4.2, docs/ACCURACY.md §4), and
// leave-one-out cannot see that. "rbf:rootpoly:2" and any other base stay available by name.
std::vector<std::string> spline_methods() { return {spline_method("ccm")}; }

std::vector<std::string> all_methods() {
  std::vector<std::string> v;
  for (const auto& s : all_term_sets()) v.push_back(s.name);
  for (auto& s : spline_methods()) v.push_back(std::move(s));
  return v;
}

Selection select_method(const std::vector<std::string>& methods, const std::vector<FitTarget>& targets, const ChartData& data,
                        const FitOptions& o, const CvSpec& cv, const SelectionOptions& so) {
  if (methods.empty() || targets.empty()) throw Error(ErrorClass::bad_parameter, "no candidate models to select from");
  if (cv.kind == CvSpec::Kind::none)
    throw Error(ErrorClass::bad_parameter, "model selection needs cross-validation, not training error");
  Selection s;
  for (const auto t : targets)
    for (const auto& m : methods) {
      FitOptions fo = o;
      fo.target = t;
      s.candidates.push_back(report_method(m, data, fo, cv));
    }
  choose_smallest_within_tolerance(s, so, data.size());
  return s;
}

}  // namespace colorlab::analysis
