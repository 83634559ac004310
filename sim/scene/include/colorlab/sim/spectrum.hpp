#pragma once
// A uniformly sampled spectrum: the value type the simulated lab passes around (lamp SPDs,
// reflectances, spectral radiance). Conversion to XYZ/Lab is colorlab_analysis's job.
#include <cstddef>
#include <vector>

namespace colorlab::sim {

struct Spectrum {
  double start_nm = 380.0;
  double step_nm = 10.0;
  std::vector<double> values;

  double end_nm() const { return values.empty() ? start_nm : start_nm + step_nm * double(values.size() - 1); }
  double wavelength(std::size_t i) const { return start_nm + step_nm * double(i); }
  // Linear interpolation between samples; 0 outside [start_nm, end_nm].
  double at(double nm) const;
  // The same spectrum sampled on another uniform grid (linear interpolation, 0 outside).
  Spectrum resampled(double start, double step, std::size_t count) const;
};

}  // namespace colorlab::sim
