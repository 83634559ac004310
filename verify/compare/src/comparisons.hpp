#pragma once
// The comparison kinds, each appending its comparisons and the scale it used to a Verification.
#include "colorlab/verify/compare/uncertainty.hpp"
#include "colorlab/verify/compare/verification.hpp"

namespace colorlab::verify::detail {

void compare_colour_73(const Rendering& r, const MeasuredScene& s, const CompareOptions& o, Verification& v);
void compare_colour_74(const Rendering& r, const MeasuredScene& s, const CompareOptions& o, Verification& v);
void compare_light(const Rendering& r, const MeasuredScene& s, const CompareOptions& o, Verification& v);

// Fills a Comparison's verdict, expanded uncertainty and per-source budget from a judged difference; `unit`
// converts the difference's coordinates into the reported difference's unit (1/|measured| for relative ones).
void conclude(Comparison& c, const Eigen::VectorXd& delta, const Budget& budget, const CompareOptions& o,
              double reported_difference, double unit, double cannot_tell_limit);

// The median of the ratios, for a fitted scale; throws Error(bad_data) when there is nothing to fit on.
double median_ratio(std::vector<double> ratios, const char* what);

}  // namespace colorlab::verify::detail
