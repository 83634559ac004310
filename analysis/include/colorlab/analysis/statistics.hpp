#pragma once
// The dissertation's summary (min, max, median, mean, standard deviation), computed in one place.
#include <cstddef>
#include <span>
#include <vector>

namespace colorlab::analysis {

struct Summary {
  std::size_t count = 0;
  double min = 0, max = 0, median = 0, mean = 0;
  double stdev = 0;  // sample standard deviation (n − 1), 0 for a single value
};

// Throws Error(bad_data) for an empty input or a non-finite value (naming its index).
Summary summarize(std::span<const double> values);
inline Summary summarize(const std::vector<double>& v) { return summarize(std::span<const double>(v)); }

}  // namespace colorlab::analysis
