#include <algorithm>
#include <cmath>
#include <numeric>

#include "internal.hpp"

namespace colorlab::analysis::chart_detail {
namespace {

std::vector<double> ranks(const std::vector<double>& v) {
  std::vector<std::size_t> idx(v.size());
  std::iota(idx.begin(), idx.end(), 0);
  std::sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) { return v[a] < v[b]; });
  std::vector<double> r(v.size());
  for (std::size_t k = 0; k < idx.size();) {
    std::size_t e = k;
    while (e + 1 < idx.size() && v[idx[e + 1]] == v[idx[k]]) ++e;
    for (std::size_t m = k; m <= e; ++m) r[idx[m]] = (k + e) / 2.0;  // ties share their mean rank
    k = e + 1;
  }
  return r;
}

}  // namespace

double spearman(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size() || a.size() < 3) return 0;
  const auto ra = ranks(a), rb = ranks(b);
  const double n = static_cast<double>(a.size()), mean = (n - 1) / 2;
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t k = 0; k < ra.size(); ++k) {
    sab += (ra[k] - mean) * (rb[k] - mean);
    saa += (ra[k] - mean) * (ra[k] - mean);
    sbb += (rb[k] - mean) * (rb[k] - mean);
  }
  return saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 0;
}

double log_correlation(const std::vector<double>& got, const std::vector<double>& want) {
  const std::size_t n = got.size();
  if (n < 3 || want.size() != n) return 0;
  std::vector<double> a(n), b(n);
  for (std::size_t k = 0; k < n; ++k) a[k] = std::log(got[k] + 1.0), b[k] = std::log(std::max(want[k], 1e-4));
  double ma = 0, mb = 0;
  for (std::size_t k = 0; k < n; ++k) ma += a[k], mb += b[k];
  ma /= double(n), mb /= double(n);
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t k = 0; k < n; ++k) sab += (a[k] - ma) * (b[k] - mb), saa += (a[k] - ma) * (a[k] - ma), sbb += (b[k] - mb) * (b[k] - mb);
  return saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 0;
}

double log_agreement(const std::vector<double>& got, const std::vector<double>& want) {
  const std::size_t n = got.size();
  if (n < 3 || want.size() != n) return 0;
  std::vector<double> a(n), b(n);
  for (std::size_t k = 0; k < n; ++k) a[k] = std::log(got[k] + 1.0), b[k] = std::log(std::max(want[k], 1e-4));
  double ma = 0, mb = 0;
  for (std::size_t k = 0; k < n; ++k) ma += a[k], mb += b[k];
  ma /= double(n), mb /= double(n);
  double sab = 0, sbb = 0;
  for (std::size_t k = 0; k < n; ++k) sab += (a[k] - ma) * (b[k] - mb), sbb += (b[k] - mb) * (b[k] - mb);
  if (!(sbb > 0)) return 0;
  const double slope = sab / sbb;
  if (!(slope > 0)) return 0;  // brighter expected must look brighter
  std::size_t inside = 0;
  for (std::size_t k = 0; k < n; ++k)
    if (std::abs(a[k] - (ma + slope * (b[k] - mb))) <= std::log(1.8)) ++inside;
  return double(inside) / double(n);
}

double working_luminance(const WorkingImage& work, cv::Point2d full, double radius_full) {
  const cv::Point2d p = work.to_working(full);
  const int r = std::max(1, static_cast<int>(radius_full * work.scale));
  const int x0 = std::max(0, static_cast<int>(p.x) - r), x1 = std::min(work.grey.cols - 1, static_cast<int>(p.x) + r);
  const int y0 = std::max(0, static_cast<int>(p.y) - r), y1 = std::min(work.grey.rows - 1, static_cast<int>(p.y) + r);
  if (x0 > x1 || y0 > y1) return 0;
  double s = 0;
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) s += work.grey.at<std::uint8_t>(y, x);
  return s / ((x1 - x0 + 1) * (y1 - y0 + 1));
}

std::vector<OrientationChoice> placements(const ChartLayout& L, const Lattice& l) {
  const double h = L.patch_size / 2, C = L.columns, R = L.rows, i0 = l.imin, j0 = l.jmin;
  std::vector<OrientationChoice> out;
  auto add = [&](int turns, cv::Matx33d m) {
    OrientationChoice o;
    o.quarter_turns = turns;
    o.grid_to_lattice = m;
    out.push_back(o);
  };
  if (l.ni() == L.columns && l.nj() == L.rows) {
    add(0, {1, 0, i0 - h, 0, 1, j0 - h, 0, 0, 1});
    add(2, {-1, 0, i0 + C - 1 + h, 0, -1, j0 + R - 1 + h, 0, 0, 1});
  }
  if (l.ni() == L.rows && l.nj() == L.columns) {
    add(1, {0, -1, i0 + R - 1 + h, 1, 0, j0 - h, 0, 0, 1});
    add(3, {0, 1, i0 - h, -1, 0, j0 + C - 1 + h, 0, 0, 1});
  }
  return out;
}

void score_placements(std::vector<OrientationChoice>& choices, const ChartLayout& L, const std::vector<double>& expected,
                      const WorkingImage& work, const Lattice& l, const std::optional<LensCalibration>& lens) {
  std::vector<int> known;
  for (int k = 0; k < L.size(); ++k)
    if (std::isfinite(expected[static_cast<std::size_t>(k)])) known.push_back(k);
  if (known.size() < 3) return;
  std::vector<double> want;
  for (int k : known) want.push_back(expected[static_cast<std::size_t>(k)]);
  for (auto& o : choices) {
    const cv::Matx33d h = l.to_image * o.grid_to_lattice;
    std::vector<double> got;
    for (int k : known)
      got.push_back(working_luminance(work, grid_to_image(h, {L.centre_x(k), L.centre_y(k)}, lens), l.pitch_px * L.patch_size / 6));
    o.score = log_agreement(got, want) + log_correlation(got, want);
    o.scored = true;
  }
  std::sort(choices.begin(), choices.end(), [](const auto& a, const auto& b) { return a.score > b.score; });
  if (choices.size() > 1) choices[0].margin = choices[0].score - choices[1].score;
  else if (!choices.empty()) choices[0].margin = choices[0].score;
}

}  // namespace colorlab::analysis::chart_detail
