#include <cmath>

#include <opencv2/calib3d.hpp>

#include "internal.hpp"

namespace colorlab::analysis::chart_detail {
namespace {

// Area centroid of a simple polygon.
cv::Point2d polygon_centroid(const std::array<cv::Point2d, 4>& q) {
  double a = 0, cx = 0, cy = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    const cv::Point2d p = q[i], n = q[(i + 1) % 4];
    const double w = p.x * n.y - n.x * p.y;
    a += w, cx += (p.x + n.x) * w, cy += (p.y + n.y) * w;
  }
  return {cx / (3 * a), cy / (3 * a)};
}

}  // namespace

std::optional<std::pair<cv::Matx33d, double>> refit_centroids(const ChartLayout& L, const cv::Matx33d& h0,
                                                              const std::vector<bool>& detected,
                                                              const std::vector<cv::Point2d>& observed) {
  std::vector<int> idx;
  for (int k = 0; k < L.size(); ++k)
    if (detected[static_cast<std::size_t>(k)]) idx.push_back(k);
  if (idx.size() < 6) return std::nullopt;
  cv::Matx33d h = h0;
  const double s = L.patch_size / 2;
  std::vector<cv::Point2d> grid, obs;
  for (int pass = 0; pass < 2; ++pass) {
    grid.clear(), obs.clear();
    for (int k : idx) {
      const cv::Point2d g(L.centre_x(k), L.centre_y(k));
      const std::array<cv::Point2d, 4> q{apply(h, g + cv::Point2d(-s, -s)), apply(h, g + cv::Point2d(s, -s)),
                                         apply(h, g + cv::Point2d(s, s)), apply(h, g + cv::Point2d(-s, s))};
      grid.push_back(g);
      obs.push_back(observed[static_cast<std::size_t>(k)] - (polygon_centroid(q) - apply(h, g)));
    }
    cv::Mat fit = cv::findHomography(grid, obs, 0);
    if (fit.empty()) return std::nullopt;
    h = cv::Matx33d(fit);
  }
  double ss = 0;
  for (std::size_t m = 0; m < grid.size(); ++m) {
    const cv::Point2d r = apply(h, grid[m]) - obs[m];
    ss += r.dot(r);
  }
  return std::pair{h, std::sqrt(ss / static_cast<double>(grid.size()))};
}

}  // namespace colorlab::analysis::chart_detail
