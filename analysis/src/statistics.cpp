#include "colorlab/analysis/statistics.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "colorlab/core/error.hpp"

namespace colorlab::analysis {

Summary summarize(std::span<const double> values) {
  if (values.empty()) throw Error(ErrorClass::bad_data, "statistics of an empty set requested");
  Summary s;
  s.count = values.size();
  // Welford's update keeps the variance exact for large, offset data (RAW counts near 4095).
  double mean = 0, m2 = 0;
  for (std::size_t i = 0; i < values.size(); ++i) {
    double v = values[i];
    if (!std::isfinite(v))
      throw Error(ErrorClass::bad_data, "statistics input value " + std::to_string(i) + " is not finite");
    double d = v - mean;
    mean += d / static_cast<double>(i + 1);
    m2 += d * (v - mean);
  }
  s.mean = mean;
  s.stdev = values.size() > 1 ? std::sqrt(m2 / static_cast<double>(values.size() - 1)) : 0.0;
  std::vector<double> sorted(values.begin(), values.end());
  std::sort(sorted.begin(), sorted.end());
  s.min = sorted.front();
  s.max = sorted.back();
  const std::size_t n = sorted.size();
  s.median = n % 2 ? sorted[n / 2] : (sorted[n / 2 - 1] + sorted[n / 2]) / 2;
  return s;
}

}  // namespace colorlab::analysis
