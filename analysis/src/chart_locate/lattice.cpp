#include <algorithm>
#include <cmath>
#include <deque>

#include <opencv2/calib3d.hpp>

#include "internal.hpp"

namespace colorlab::analysis::chart_detail {
namespace {

double norm(cv::Point2d p) { return std::hypot(p.x, p.y); }
double cross(cv::Point2d a, cv::Point2d b) { return a.x * b.y - a.y * b.x; }
bool similar_size(double a, double b) { return a < 1.6 * b && b < 1.6 * a; }

// The neighbour of quad k nearest along ±dir, within [0.9, 1.8] sides (one pitch). Returns the displacement.
std::optional<cv::Point2d> neighbour_along(const std::vector<Quad>& quads, const std::vector<cv::Point2d>& c, std::size_t k,
                                           cv::Point2d dir) {
  std::optional<cv::Point2d> best;
  double best_len = 0;
  const double side = quads[k].side;
  for (std::size_t q = 0; q < quads.size(); ++q) {
    if (q == k || !similar_size(quads[q].side, side)) continue;
    const cv::Point2d d = c[q] - c[k];
    const double len = norm(d);
    if (len < 0.9 * side || len > 1.8 * side) continue;
    const double cosang = (d.x * dir.x + d.y * dir.y) / (len * norm(dir));
    if (std::abs(cosang) < std::cos(20.0 * CV_PI / 180.0)) continue;
    if (!best || len < best_len) best = cosang > 0 ? d : -d, best_len = len;
  }
  return best;
}

struct Seed {
  std::size_t quad = 0;
  cv::Point2d a, b;
};

std::optional<Seed> seed_at(const std::vector<Quad>& quads, const std::vector<cv::Point2d>& c, std::size_t k) {
  const auto& p = quads[k].corners;
  const cv::Point2d e1 = ((p[1] - p[0]) + (p[2] - p[3])) * 0.5, e2 = ((p[3] - p[0]) + (p[2] - p[1])) * 0.5;
  auto a = neighbour_along(quads, c, k, e1), b = neighbour_along(quads, c, k, e2);
  if (!a || !b) return std::nullopt;
  Seed s{k, *a, *b};
  if (cross(s.a, s.b) < 0) s.b = -s.b;  // right-handed like the chart's (column, row) in an unmirrored photo
  return s;
}

Lattice grow(const std::vector<Quad>& quads, const std::vector<cv::Point2d>& c, const Seed& seed) {
  Lattice l;
  std::vector<std::optional<std::pair<int, int>>> at(quads.size());
  struct Node {
    std::size_t quad;
    int i, j;
    cv::Point2d a, b;
  };
  std::deque<Node> queue{{seed.quad, 0, 0, seed.a, seed.b}};
  at[seed.quad] = std::pair{0, 0};
  l.cells[{0, 0}] = static_cast<int>(seed.quad);
  while (!queue.empty()) {
    const Node n = queue.front();
    queue.pop_front();
    const double det = cross(n.a, n.b), reach = 2.6 * std::max(norm(n.a), norm(n.b));
    for (std::size_t q = 0; q < quads.size(); ++q) {
      if (at[q] || !similar_size(quads[q].side, quads[n.quad].side)) continue;
      const cv::Point2d d = c[q] - c[n.quad];
      if (norm(d) > reach) continue;
      const double al = cross(d, n.b) / det, be = cross(n.a, d) / det;
      const double ai = std::round(al), bi = std::round(be);
      if (std::abs(al - ai) > 0.25 || std::abs(be - bi) > 0.25 || (ai == 0 && bi == 0)) continue;
      if (std::abs(ai) > 2 || std::abs(bi) > 2) continue;
      const std::pair<int, int> cell{n.i + static_cast<int>(ai), n.j + static_cast<int>(bi)};
      if (l.cells.count(cell)) continue;
      at[q] = cell;
      l.cells[cell] = static_cast<int>(q);
      queue.push_back({q, cell.first, cell.second, bi == 0 ? d / ai : n.a, ai == 0 ? d / bi : n.b});
    }
  }
  return l;
}

void set_extent(Lattice& l) {
  l.imin = l.jmin = 1 << 20;
  l.imax = l.jmax = -(1 << 20);
  for (const auto& [cell, q] : l.cells) {
    l.imin = std::min(l.imin, cell.first), l.imax = std::max(l.imax, cell.first);
    l.jmin = std::min(l.jmin, cell.second), l.jmax = std::max(l.jmax, cell.second);
  }
}

// Fits the homography to the assigned cells; with RANSAC drops cells that do not fit. False when it cannot.
bool fit(Lattice& l, const std::vector<cv::Point2d>& c, bool ransac) {
  if (l.cells.size() < 6) return false;
  std::vector<cv::Point2d> src, dst;
  std::vector<std::pair<int, int>> keys;
  for (const auto& [cell, q] : l.cells) {
    src.emplace_back(cell.first, cell.second);
    dst.push_back(c[static_cast<std::size_t>(q)]);
    keys.push_back(cell);
  }
  std::vector<unsigned char> inlier;
  const double threshold = l.pitch_px > 0 ? 0.15 * l.pitch_px : 3.0;
  cv::Mat h = cv::findHomography(src, dst, ransac ? cv::RANSAC : 0, threshold, inlier);
  if (h.empty()) return false;
  l.to_image = cv::Matx33d(h);
  if (ransac)
    for (std::size_t k = 0; k < keys.size(); ++k)
      if (!inlier[k]) l.cells.erase(keys[k]);
  const cv::Point2d mid((l.imin + l.imax) / 2.0, (l.jmin + l.jmax) / 2.0);
  const cv::Point2d o = apply(l.to_image, mid);
  l.pitch_px = (norm(apply(l.to_image, mid + cv::Point2d(1, 0)) - o) + norm(apply(l.to_image, mid + cv::Point2d(0, 1)) - o)) / 2;
  double ss = 0;
  for (const auto& [cell, q] : l.cells) {
    const cv::Point2d r = apply(l.to_image, cv::Point2d(cell.first, cell.second)) - c[static_cast<std::size_t>(q)];
    ss += r.dot(r);
  }
  l.rms_px = std::sqrt(ss / static_cast<double>(std::max<std::size_t>(1, l.cells.size())));
  return l.cells.size() >= 6;
}

}  // namespace

std::optional<Lattice> build_lattice(const std::vector<Quad>& quads, const std::vector<cv::Point2d>& c, int min_cells) {
  if (quads.size() < static_cast<std::size_t>(std::max(6, min_cells))) return std::nullopt;
  // Try the quads with the most complete neighbourhoods as seeds; keep the largest lattice.
  std::vector<std::pair<int, std::size_t>> order;
  for (std::size_t k = 0; k < quads.size(); ++k) {
    int n = 0;
    for (std::size_t q = 0; q < quads.size(); ++q)
      if (q != k && similar_size(quads[q].side, quads[k].side) && norm(c[q] - c[k]) < 1.8 * quads[k].side) ++n;
    order.emplace_back(-n, k);
  }
  std::sort(order.begin(), order.end());
  std::optional<Lattice> best;
  std::vector<bool> used(quads.size(), false);
  int tries = 0;
  for (const auto& [neg, k] : order) {
    if (tries >= 6 || -neg < 2) break;
    if (used[k]) continue;
    const auto seed = seed_at(quads, c, k);
    if (!seed) continue;
    ++tries;
    Lattice l = grow(quads, c, *seed);
    for (const auto& [cell, q] : l.cells) used[static_cast<std::size_t>(q)] = true;
    if (static_cast<int>(l.cells.size()) < min_cells) continue;
    set_extent(l);
    if (!fit(l, c, true)) continue;
    set_extent(l);
    for (int pass = 0; pass < 2; ++pass) {
      refine_lattice(l, c, l.imin - 1, l.imax + 1, l.jmin - 1, l.jmax + 1);
      set_extent(l);
    }
    if (static_cast<int>(l.cells.size()) < min_cells) continue;
    if (!best || l.cells.size() > best->cells.size()) best = std::move(l);
  }
  return best;
}

void refine_lattice(Lattice& l, const std::vector<cv::Point2d>& c, int imin, int imax, int jmin, int jmax) {
  const cv::Matx33d inv = l.to_image.inv();
  std::vector<double> sides;
  std::map<std::pair<int, int>, std::pair<int, double>> best;
  for (std::size_t q = 0; q < c.size(); ++q) {
    const cv::Point2d g = apply(inv, c[q]);
    const int i = static_cast<int>(std::lround(g.x)), j = static_cast<int>(std::lround(g.y));
    if (i < imin || i > imax || j < jmin || j > jmax) continue;
    const double off = std::hypot(g.x - i, g.y - j);
    if (off > 0.3) continue;
    auto it = best.find({i, j});
    if (it == best.end() || off < it->second.second) best[{i, j}] = {static_cast<int>(q), off};
  }
  if (best.size() < 6) return;
  Lattice next = l;
  next.cells.clear();
  for (const auto& [cell, qo] : best) next.cells[cell] = qo.first;
  if (fit(next, c, true)) l = std::move(next);
}

}  // namespace colorlab::analysis::chart_detail
