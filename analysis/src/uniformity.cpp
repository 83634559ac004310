#include "colorlab/analysis/uniformity.hpp"

#include <cmath>

#include "colorlab/analysis/statistics.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::analysis {

Eigen::MatrixXd mirror_left_half(const Eigen::MatrixXd& left) {
  if (left.size() == 0) throw Error(ErrorClass::bad_data, "uniformity grid is empty");
  for (Eigen::Index r = 0; r < left.rows(); ++r)
    for (Eigen::Index c = 0; c < left.cols(); ++c)
      if (!std::isfinite(left(r, c)) || left(r, c) < 0)
        throw Error(ErrorClass::bad_data, "uniformity grid value at row " + std::to_string(r + 1) + ", column " +
                                              std::to_string(c + 1) + " is " + std::to_string(left(r, c)));
  Eigen::MatrixXd full(left.rows(), 2 * left.cols());
  full.leftCols(left.cols()) = left;
  full.rightCols(left.cols()) = left.rowwise().reverse();
  return full;
}

UniformityResult analyse_uniformity(const Eigen::MatrixXd& left, const UniformityOptions& opt) {
  UniformityResult res;
  res.full = mirror_left_half(left);
  const int wr = opt.window_rows, wc = opt.window_cols;
  if (wr < 1 || wc < 1) throw Error(ErrorClass::bad_parameter, "window must be at least 1x1");
  if (res.full.rows() < wr || res.full.cols() < wc)
    throw Error(ErrorClass::bad_data, "mirrored grid " + std::to_string(res.full.rows()) + "x" +
                                          std::to_string(res.full.cols()) + " is smaller than the " +
                                          std::to_string(wr) + "x" + std::to_string(wc) + " window");
  res.min = res.full.minCoeff();
  res.max = res.full.maxCoeff();
  res.difference = res.full.array() - res.min;
  res.window_stdev.resize(res.full.rows() - wr + 1, res.full.cols() - wc + 1);
  res.best.stdev = INFINITY;
  std::vector<double> v(static_cast<std::size_t>(wr * wc));
  for (Eigen::Index i = 0; i < res.window_stdev.rows(); ++i)
    for (Eigen::Index j = 0; j < res.window_stdev.cols(); ++j) {
      Eigen::MatrixXd w = res.difference.block(i, j, wr, wc);
      std::copy(w.data(), w.data() + w.size(), v.begin());
      const double sd = summarize(v).stdev;
      res.window_stdev(i, j) = sd;
      // Strictly smaller keeps the first (top-left-most) of mirror-symmetric ties.
      if (sd < res.best.stdev - 1e-12) res.best = {static_cast<int>(i), static_cast<int>(j), sd};
    }
  return res;
}

DimmerCheck dimmer_proportionality(const Eigen::MatrixXd& full, const Eigen::MatrixXd& low, double setting) {
  if (!(setting > 0 && setting <= 1))
    throw Error(ErrorClass::bad_parameter, "dimmer setting must be in (0, 1], got " + std::to_string(setting));
  if (full.rows() != low.rows() || full.cols() != low.cols())
    throw Error(ErrorClass::bad_data, "dimmer grids differ in size");
  DimmerCheck d;
  d.setting = setting;
  d.scaled = low / setting;
  d.error = full - d.scaled;
  d.max_abs_error = d.error.cwiseAbs().maxCoeff();
  return d;
}

std::vector<LampSummary> compare_lamps(const std::vector<std::string>& names,
                                       const std::vector<UniformityResult>& results) {
  if (names.size() != results.size()) throw Error(ErrorClass::bad_data, "lamp names and results differ in number");
  std::vector<LampSummary> out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto& r = results[i];
    out.push_back({names[i], r.min, r.max, r.max - r.min, r.best, r.window_stdev.maxCoeff()});
  }
  return out;
}

}  // namespace colorlab::analysis
