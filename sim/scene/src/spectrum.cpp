#include "colorlab/sim/spectrum.hpp"

#include <cmath>

namespace colorlab::sim {

double Spectrum::at(double nm) const {
  if (values.empty() || nm < start_nm - 1e-9 || nm > end_nm() + 1e-9) return 0.0;
  const double pos = (nm - start_nm) / step_nm;
  const auto i = static_cast<std::size_t>(std::floor(pos));
  if (i + 1 >= values.size()) return values.back();
  const double t = pos - double(i);
  return values[i] * (1.0 - t) + values[i + 1] * t;
}

Spectrum Spectrum::resampled(double start, double step, std::size_t count) const {
  Spectrum out{start, step, std::vector<double>(count)};
  for (std::size_t i = 0; i < count; ++i) out.values[i] = at(start + step * double(i));
  return out;
}

}  // namespace colorlab::sim
