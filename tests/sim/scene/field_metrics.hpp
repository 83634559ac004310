#pragma once
// The §6.2 uniformity numbers, computed the dissertation's way, to test the simulated field against.
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>

#include "colorlab/sim/scene.hpp"

namespace colorlab::sim::test {

using Grid = std::array<std::array<double, floor_cols>, floor_rows>;

inline Grid sample_grid(const std::function<double(double, double)>& f) {
  Grid g{};
  for (int r = 0; r < floor_rows; ++r)
    for (int c = 0; c < floor_cols; ++c) {
      const auto [x, y] = Scene::floor_spot_position_mm(r, c);
      g[r][c] = f(x, y);
    }
  return g;
}

inline double grid_min(const Grid& g) {
  double m = g[0][0];
  for (const auto& row : g)
    for (double v : row) m = std::min(m, v);
  return m;
}
inline double grid_max(const Grid& g) {
  double m = g[0][0];
  for (const auto& row : g)
    for (double v : row) m = std::max(m, v);
  return m;
}

// Standard deviation (population) of every 4×5 window; returns the smallest.
inline double best_window_std(const Grid& g) {
  double best = 1e300;
  for (int r0 = 0; r0 + 4 <= floor_rows; ++r0)
    for (int c0 = 0; c0 + 5 <= floor_cols; ++c0) {
      double s = 0, s2 = 0;
      for (int r = r0; r < r0 + 4; ++r)
        for (int c = c0; c < c0 + 5; ++c) s += g[r][c], s2 += g[r][c] * g[r][c];
      const double mean = s / 20;
      best = std::min(best, std::sqrt(std::max(s2 / 20 - mean * mean, 0.0)));
    }
  return best;
}

// §6.2, figs. 39–41: subtract each grid's minimum, scale the dimmed grid by 100/d, compare with 100 %.
inline double dimmer_scaled_max_error(const Grid& full, const Grid& dimmed, double percent) {
  const double m100 = grid_min(full), md = grid_min(dimmed);
  double worst = 0;
  for (int r = 0; r < floor_rows; ++r)
    for (int c = 0; c < floor_cols; ++c)
      worst = std::max(worst, std::abs((full[r][c] - m100) - (dimmed[r][c] - md) * 100.0 / percent));
  return worst;
}

}  // namespace colorlab::sim::test
