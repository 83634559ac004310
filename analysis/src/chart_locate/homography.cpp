#include "internal.hpp"

namespace colorlab::analysis::chart_detail {

cv::Point2d apply(const cv::Matx33d& h, cv::Point2d p) {
  const cv::Vec3d v = h * cv::Vec3d(p.x, p.y, 1.0);
  return {v[0] / v[2], v[1] / v[2]};
}

std::array<double, 9> to_array(const cv::Matx33d& h) {
  std::array<double, 9> a{};
  for (int i = 0; i < 9; ++i) a[static_cast<std::size_t>(i)] = h.val[i] / h.val[8];
  return a;
}

cv::Matx33d from_array(const std::array<double, 9>& a) {
  cv::Matx33d h;
  for (int i = 0; i < 9; ++i) h.val[i] = a[static_cast<std::size_t>(i)];
  return h;
}

}  // namespace colorlab::analysis::chart_detail
