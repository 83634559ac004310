#pragma once
// Chapter 7 (b): camera input ICC profiles built from chart data with lcms2 (matrix/shaper and LUT), and applied.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "colorlab/analysis/regression.hpp"

namespace colorlab::analysis {

// A serialised ICC profile (v2.4 input class, D50 PCS).
struct IccProfile {
  std::vector<std::uint8_t> bytes;
  void save(const std::filesystem::path& path) const;  // throws Error(io_error)
};

// Matrix/shaper: TRC = device^gamma per channel (1.0 for linear RAW-derived RGB, about 2.2 for developed images),
// colorants from a least-squares fit of linearised RGB (0–1) to chart XYZ (PCS XYZ, relative to the ICC D50 white).
IccProfile build_matrix_shaper_profile(const ChartData& chart, double gamma = 1.0,
                                       const std::string& description = "colorlab matrix/shaper");

// LUT: cube-root input curves and an AToB0 colour lookup table (grid_points³, RGB → PCS L*a*b*) sampled from a
// fitted model; device value 1.0
// corresponds to `rgb_full_scale` in the model's input units.
IccProfile build_lut_profile(const PolynomialModel& model, int grid_points = 33, double rgb_full_scale = 1.0,
                             const std::string& description = "colorlab LUT");

// Device RGB (0–1) through the profile with lcms2 (relative colorimetric) to L*a*b* D50: n × 3.
Eigen::MatrixXd apply_profile(const IccProfile& profile, const Eigen::MatrixXd& rgb);

}  // namespace colorlab::analysis
