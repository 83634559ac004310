#include <opencv2/calib3d.hpp>

#include "internal.hpp"

namespace colorlab::analysis::chart_detail {

std::vector<cv::Point2d> undistort_points(const std::vector<cv::Point2d>& pts, const std::optional<LensCalibration>& lens) {
  if (!lens || pts.empty()) return pts;
  const cv::Matx33d K(lens->fx, 0, lens->cx, 0, lens->fy, lens->cy, 0, 0, 1);
  const cv::Matx<double, 1, 5> D(lens->k1, lens->k2, lens->p1, lens->p2, lens->k3);
  std::vector<cv::Point2d> out;
  cv::undistortPoints(pts, out, K, D, cv::noArray(), K,
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 1e-6));
  return out;
}

cv::Point2d distort_point(cv::Point2d p, const std::optional<LensCalibration>& lens) {
  if (!lens) return p;
  const LensCalibration& l = *lens;
  // Brown–Conrady, as cv::projectPoints applies it.
  const double x = (p.x - l.cx) / l.fx, y = (p.y - l.cy) / l.fy, r2 = x * x + y * y;
  const double radial = 1 + l.k1 * r2 + l.k2 * r2 * r2 + l.k3 * r2 * r2 * r2;
  const double xd = x * radial + 2 * l.p1 * x * y + l.p2 * (r2 + 2 * x * x);
  const double yd = y * radial + l.p1 * (r2 + 2 * y * y) + 2 * l.p2 * x * y;
  return {l.cx + l.fx * xd, l.cy + l.fy * yd};
}

}  // namespace colorlab::analysis::chart_detail
