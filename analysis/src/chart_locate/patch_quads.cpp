#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "internal.hpp"

namespace colorlab::analysis::chart_detail {
namespace {

double dist(cv::Point2d a, cv::Point2d b) { return std::hypot(a.x - b.x, a.y - b.y); }

// A convex quadrilateral whose sides and diagonals are alike enough to be a patch seen at up to ~60° of tilt.
bool patch_like(const std::vector<cv::Point>& q, double region_area) {
  if (q.size() != 4 || !cv::isContourConvex(q)) return false;
  double s[4];
  for (int i = 0; i < 4; ++i) s[i] = dist(q[static_cast<std::size_t>(i)], q[static_cast<std::size_t>((i + 1) % 4)]);
  const double smin = *std::min_element(s, s + 4), smax = *std::max_element(s, s + 4);
  if (smin <= 0 || smax / smin > 2.5) return false;
  const double d1 = dist(q[0], q[2]), d2 = dist(q[1], q[3]);
  if (std::max(d1, d2) / std::min(d1, d2) > 1.8) return false;
  const double poly = cv::contourArea(q);
  return poly > 0 && region_area / poly > 0.8 && region_area / poly < 1.25;
}

}  // namespace

std::vector<Quad> find_patch_quads(const WorkingImage& work) {
  const cv::Mat& g = work.grey;
  cv::Mat blurred, bin;
  cv::GaussianBlur(g, blurred, cv::Size(3, 3), 0);
  // Local-mean threshold: each patch becomes a bright region ringed by the dark side of its edges.
  const int block = std::max(11, (std::min(g.cols, g.rows) / 50) | 1);
  cv::adaptiveThreshold(blurred, bin, 255, cv::ADAPTIVE_THRESH_MEAN_C, cv::THRESH_BINARY, block, 3);
  cv::morphologyEx(bin, bin, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3)));
  cv::morphologyEx(bin, bin, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3)));
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(bin, contours, cv::RETR_LIST, cv::CHAIN_APPROX_SIMPLE);

  const double min_area = 64, max_area = double(g.cols) * g.rows / 12.0;
  std::vector<Quad> quads;
  std::vector<cv::Point> approx;
  for (const auto& c : contours) {
    const double area = cv::contourArea(c);
    if (area < min_area || area > max_area) continue;
    cv::approxPolyDP(c, approx, 0.06 * cv::arcLength(c, true), true);
    if (!patch_like(approx, area)) continue;
    const cv::Moments m = cv::moments(c);
    if (m.m00 <= 0) continue;
    Quad q;
    q.centre = work.to_full({m.m10 / m.m00, m.m01 / m.m00});
    for (int i = 0; i < 4; ++i)
      q.corners[static_cast<std::size_t>(i)] = work.to_full(cv::Point2d(approx[static_cast<std::size_t>(i)]));
    double s = 0;
    for (int i = 0; i < 4; ++i) s += dist(q.corners[static_cast<std::size_t>(i)], q.corners[static_cast<std::size_t>((i + 1) % 4)]);
    q.side = s / 4;
    quads.push_back(q);
  }
  // Nested outlines of one patch (its bright region and the hole it leaves in the surround): keep the larger.
  std::sort(quads.begin(), quads.end(), [](const Quad& a, const Quad& b) { return a.side > b.side; });
  std::vector<Quad> kept;
  for (const auto& q : quads) {
    bool dup = false;
    for (const auto& k : kept)
      if (dist(q.centre, k.centre) < 0.35 * k.side) dup = true;
    if (!dup) kept.push_back(q);
  }
  return kept;
}

}  // namespace colorlab::analysis::chart_detail
