#pragma once
// Light-cabinet uniformity (dissertation §6.2): spot grids, chart placement, dimmer proportionality.
#include <Eigen/Dense>
#include <string>
#include <vector>

namespace colorlab::analysis {

struct UniformityOptions {
  int window_rows = 4;  // the SG's white border patches: 4 × 5
  int window_cols = 5;
};

struct WindowPosition {
  int row = 0, col = 0;
  double stdev = 0;
};

struct UniformityResult {
  Eigen::MatrixXd full;        // mirrored grid (8 × 20), absolute luminance
  Eigen::MatrixXd difference;  // full minus its minimum
  double min = 0, max = 0;
  Eigen::MatrixXd window_stdev;  // (rows − wr + 1) × (cols − wc + 1): Tables 3–6
  WindowPosition best;
};

// The cabinet is symmetric, so only the left half is measured: column j of the right half mirrors column
// (cols − 1 − j) of the left. Throws Error(bad_data) for NaN, negative values or a grid smaller than a window.
Eigen::MatrixXd mirror_left_half(const Eigen::MatrixXd& left_half);
UniformityResult analyse_uniformity(const Eigen::MatrixXd& left_half, const UniformityOptions& options = {});

struct DimmerCheck {
  double setting = 0;      // e.g. 0.5
  Eigen::MatrixXd scaled;  // lower setting's difference grid × 1/setting
  Eigen::MatrixXd error;   // full-power difference grid − scaled
  double max_abs_error = 0;
};
// Both grids are mirrored grids' difference distributions (as analyse_uniformity().difference).
DimmerCheck dimmer_proportionality(const Eigen::MatrixXd& full_difference, const Eigen::MatrixXd& low_difference,
                                   double setting);

struct LampSummary {
  std::string name;
  double min = 0, max = 0, range = 0;
  WindowPosition best;
  double worst_window = 0;
};
std::vector<LampSummary> compare_lamps(const std::vector<std::string>& names,
                                       const std::vector<UniformityResult>& results);

}  // namespace colorlab::analysis
