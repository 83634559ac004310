#include "rendering_noise.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>

#include "colorlab/core/error.hpp"
#include "colorlab/verify/compare/uncertainty.hpp"
#include "rendering_sample.hpp"

namespace colorlab::verify::detail {
namespace {

// The noise is read in each region's central window of at most kWindow × kWindow pixels (576 pixels say its level
// well enough; a floor cell of a full-size rendering would otherwise cost a model of every size it comes in), and a
// region's mean gets the variance of its whole w × h.
constexpr int kWindow = 24;

struct Lag {
  int dx = 0, dy = 0;
  bool operator==(const Lag& o) const { return dx == o.dx && dy == o.dy; }
};

// Lag 0 and one of each ± pair of lags within L pixels (the half-plane).
std::vector<Lag> lags_within(int l) {
  std::vector<Lag> out{{0, 0}};
  for (int dy = 0; dy <= l; ++dy)
    for (int dx = -l; dx <= l; ++dx)
      if (dy > 0 || dx > 0) out.push_back({dx, dy});
  return out;
}

// Pixel pairs at lag d inside a w × h window (N for lag 0).
double pairs(const Lag& d, int w, int h) { return std::max(0, w - std::abs(d.dx)) * std::max(0, h - std::abs(d.dy)); }

// Rows are the window's pixels, p = y·w + x. (A_d Y)_p = Y_{p+d} inside the window, else 0.
Eigen::MatrixXd shift(const Eigen::MatrixXd& y, int w, int h, int dx, int dy) {
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(y.rows(), y.cols());
  for (int yy = 0; yy < h; ++yy) {
    const int sy = yy + dy;
    if (sy < 0 || sy >= h) continue;
    for (int xx = 0; xx < w; ++xx) {
      const int sx = xx + dx;
      if (sx >= 0 && sx < w) out.row(yy * w + xx) = y.row(sy * w + sx);
    }
  }
  return out;
}

// B_d = A_d + A_dᵀ: the symmetric lag-d part of a covariance (the identity for lag 0).
Eigen::MatrixXd both_ways(const Eigen::MatrixXd& y, int w, int h, const Lag& d) {
  if (d.dx == 0 && d.dy == 0) return y;
  return shift(y, w, h, d.dx, d.dy) + shift(y, w, h, -d.dx, -d.dy);
}

// What depends only on a region's size: the plane's design X (1, x, y centred), (XᵀX)⁻¹, and the expected lag
// products of the plane's residuals per unit of each lag's covariance, K(e, d) = tr(A_e P B_d P) with
// P = I − X(XᵀX)⁻¹Xᵀ — written out in X so that nothing N × N is formed.
struct Window {
  Eigen::MatrixXd x;
  Eigen::Matrix3d g;
  Eigen::MatrixXd k;
};

Window window(int w, int h, const std::vector<Lag>& lags) {
  Window m;
  m.x.resize(w * h, 3);
  for (int yy = 0; yy < h; ++yy)
    for (int xx = 0; xx < w; ++xx) m.x.row(yy * w + xx) << 1.0, xx - 0.5 * (w - 1), yy - 0.5 * (h - 1);
  m.g = (m.x.transpose() * m.x).inverse();
  const auto n = static_cast<Eigen::Index>(lags.size());
  m.k.resize(n, n);
  std::vector<Eigen::MatrixXd> b_x;
  for (const Lag& ld : lags) b_x.push_back(both_ways(m.x, w, h, ld));
  for (Eigen::Index e = 0; e < n; ++e) {
    const Lag& le = lags[static_cast<std::size_t>(e)];
    const Eigen::MatrixXd ae_x = shift(m.x, w, h, le.dx, le.dy);
    for (Eigen::Index d = 0; d < n; ++d) {
      const Lag& ld = lags[static_cast<std::size_t>(d)];
      const Eigen::MatrixXd& bd_x = b_x[static_cast<std::size_t>(d)];
      double t = le == ld ? pairs(le, w, h) : 0.0;                                     // tr(A_e B_d)
      t -= (m.g * (m.x.transpose() * both_ways(ae_x, w, h, ld))).trace();              // tr(A_e H B_d)
      t -= (m.g * (m.x.transpose() * shift(bd_x, w, h, le.dx, le.dy))).trace();        // tr(A_e B_d H)
      t += (m.g * (m.x.transpose() * ae_x) * m.g * (m.x.transpose() * bd_x)).trace();  // tr(A_e H B_d H)
      m.k(e, d) = t;
    }
  }
  return m;
}

// The Satterthwaite degrees of freedom of one coordinate's residual sum of squares when the noise has the lag
// correlations ρ: (tr PR)² / tr(PRPR), R = Σ_d ρ_d B_d — what a χ² with that many degrees of freedom must stand for
// when a region's level is compared with its neighbours'. tr(PRPR) = tr(RR) − 2 tr(G (RX)ᵀ RX) + tr((G XᵀRX)²),
// again in X so that nothing N × N is formed.
double residual_dof(const Window& m, int w, int h, const std::vector<Lag>& lags, const Eigen::VectorXd& rho) {
  const double n = static_cast<double>(w) * h;
  Eigen::MatrixXd rx = m.x;
  double rr = n;
  for (std::size_t d = 1; d < lags.size(); ++d) {
    const double r = rho[static_cast<Eigen::Index>(d)];
    rx += r * both_ways(m.x, w, h, lags[d]);
    rr += 2 * pairs(lags[d], w, h) * r * r;
  }
  const Eigen::Matrix3d gxrx = m.g * (m.x.transpose() * rx);
  const double pr = m.k.row(0).transpose().dot(rho);
  const double prpr = rr - 2 * (m.g * (rx.transpose() * rx)).trace() + (gxrx * gxrx).trace();
  if (!(pr > 0) || !(prpr > 0)) return 1;
  return std::clamp(pr * pr / prpr, 1.0, n - 3);
}

// The screen that keeps a region's residuals out of its neighbours' pooled level when they are not noise (a texture,
// an edge the region catches, a firefly): each region's level against the median of the levels of the (at least 8)
// regions nearest it. A level estimated from ν degrees of freedom is σ² χ²_ν/ν, whose median is below σ² (0.89 σ² for
// ν = 6), so the median is divided by that factor before it stands for σ²; a region is left out beyond the χ²_ν/ν
// quantile at kScreenP. Simulated with 8 neighbours of a clean noise, this leaves out 0.07–0.18 % of clean regions
// (ν = 22 … 3), each of them a top-of-the-tail value whose loss lowers a pooled level by well under 1 %.
constexpr int kScreenAtLeast = 8;
constexpr std::size_t kScreenMin = 4;  // fewer others to compare with: nothing is left out
constexpr double kScreenP = 0.9999;

struct RegionStats {
  Eigen::VectorXd mean, scale;  // the region's mean, and what its residuals are taken relative to
  bool usable = false;          // pixels enough beyond the plane, and not black
  Eigen::MatrixXd s;            // Σ over pixels of the relative residuals' outer products
  Eigen::VectorXd q;            // Σ of the relative residuals' lag products, per lag (summed over coordinates)
  double cx = 0, cy = 0;        // centre, for the neighbours
};

}  // namespace

RenderingNoise rendering_noise(const Rendering& r, const std::vector<PixelRect>& regions, const Eigen::MatrixXd& to,
                               int neighbours) {
  if (neighbours < 1)
    throw Error(ErrorClass::bad_parameter,
                "noise_neighbours must be at least 1 (got " + std::to_string(neighbours) + ")",
                "the rendering's noise level is pooled over that many nearest regions; 8 is the default");
  RenderingNoise out;
  out.left_out.assign(regions.size(), false);  // per region, as documented, on every return
  if (regions.empty()) return out;
  const auto dim = to.rows();
  const int channels = r.channels();
  auto estimated_in = [](const PixelRect& g) {
    const int w = std::min(g.w, kWindow), h = std::min(g.h, kWindow);
    return PixelRect{g.x + (g.w - w) / 2, g.y + (g.h - h) / 2, w, h};
  };
  bool any = false, all_large = true;
  for (const auto& full : regions)
    if (const PixelRect g = estimated_in(full); g.w >= 2 && g.h >= 2 && g.w * g.h >= 8) {
      any = true;
      all_large = all_large && g.w >= 6 && g.h >= 6;
    }
  if (!any) return out;
  const std::vector<Lag> lags = lags_within(all_large ? 2 : 1);
  const auto n_lags = static_cast<Eigen::Index>(lags.size());
  std::map<std::pair<int, int>, Window> windows;
  auto window_of = [&](std::size_t i) -> const Window& {
    const PixelRect g = estimated_in(regions[i]);
    auto it = windows.find({g.w, g.h});
    if (it == windows.end()) it = windows.emplace(std::pair{g.w, g.h}, window(g.w, g.h, lags)).first;
    return it->second;
  };

  std::vector<RegionStats> stats(regions.size());
  for (std::size_t i = 0; i < regions.size(); ++i) {
    const PixelRect g = estimated_in(regions[i]);
    auto& st = stats[i];
    st.cx = g.x + 0.5 * g.w;
    st.cy = g.y + 0.5 * g.h;
    Eigen::MatrixXd y(static_cast<Eigen::Index>(g.w) * g.h, dim);  // the region's pixels in the compared coordinates
    for (int yy = 0; yy < g.h; ++yy)
      for (int xx = 0; xx < g.w; ++xx) {
        const float* p = r.pixel(g.x + xx, g.y + yy);
        const Eigen::VectorXd c = Eigen::Map<const Eigen::VectorXf>(p, channels).cast<double>();
        y.row(yy * g.w + xx) = (to * c).transpose();
      }
    st.mean = y.colwise().mean().transpose();
    const double norm = st.mean.norm();
    st.scale = st.mean.cwiseAbs().cwiseMax(1e-3 * norm);
    if (!(norm > 0) || g.w < 2 || g.h < 2 || g.w * g.h < 8) continue;
    const Window& win = window_of(i);
    const Eigen::MatrixXd beta = win.g * (win.x.transpose() * y);
    const Eigen::MatrixXd rel = (y - win.x * beta) * st.scale.cwiseInverse().asDiagonal();
    st.s = rel.transpose() * rel;
    st.q.resize(n_lags);
    for (std::size_t e = 0; e < lags.size(); ++e)
      st.q[static_cast<Eigen::Index>(e)] = rel.cwiseProduct(shift(rel, g.w, g.h, lags[e].dx, lags[e].dy)).sum();
    st.usable = true;
  }

  // The correlation's shape from the regions with weight w_j > 0, each one's lag products times w_j: c = K⁻¹ q,
  // ρ_d = c_d / c_0; white (ρ = 0) when the system says nothing (a rendering without noise, or regions too alike in
  // size to separate the lags).
  auto correlation = [&](const std::vector<double>& weight) {
    Eigen::VectorXd q = Eigen::VectorXd::Zero(n_lags);
    Eigen::MatrixXd k = Eigen::MatrixXd::Zero(n_lags, n_lags);
    for (std::size_t j = 0; j < regions.size(); ++j)
      if (stats[j].usable && weight[j] > 0) {
        q += weight[j] * stats[j].q;
        k += window_of(j).k * static_cast<double>(dim);  // every coordinate contributes its lag products
      }
    Eigen::VectorXd rho = Eigen::VectorXd::Zero(n_lags);
    rho[0] = 1;
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(k);
    if (lu.isInvertible() && q[0] > 0) {
      const Eigen::VectorXd c = lu.solve(q);
      if (c[0] > 0 && c.allFinite()) rho = (c / c[0]).cwiseMax(-1.0).cwiseMin(1.0);
    }
    return rho;
  };
  // Each region's residual sum of squares per pixel against what it is expected to be per unit variance, given the
  // plane and the correlation: its relative noise level (0 when the region says nothing).
  auto expected = [&](std::size_t i, const Eigen::VectorXd& rho) { return stats[i].usable ? window_of(i).k.row(0).transpose().dot(rho) : 0.0; };

  // Pass 1, the screen. The shape from every region, each one's lag products divided by its own level (so a region
  // with residuals a hundred times the noise counts for its pixels, not for its variance — a checkerboard's would
  // otherwise make the whole rendering's noise look anti-correlated); then each region's level and degrees of
  // freedom under that shape, and the regions whose level their neighbours' median cannot explain.
  std::vector<double> level(regions.size(), 0.0), dof(regions.size(), 1.0);
  std::vector<bool> has(regions.size(), false);  // a level to compare (a noise-free region's is 0, and counts)
  {
    std::vector<double> w(regions.size(), 0.0);
    for (std::size_t j = 0; j < regions.size(); ++j)
      if (stats[j].usable && stats[j].q[0] > 0) w[j] = static_cast<double>(dim) * window_of(j).k(0, 0) / stats[j].q[0];
    const Eigen::VectorXd rho = correlation(w);
    for (std::size_t j = 0; j < regions.size(); ++j) {
      const double e = expected(j, rho);
      if (!(e > 0)) continue;
      has[j] = true;
      level[j] = stats[j].s.trace() / (static_cast<double>(dim) * e);
      const PixelRect g = estimated_in(regions[j]);
      dof[j] = residual_dof(window_of(j), g.w, g.h, lags, rho);
    }
  }
  const auto screen_n = static_cast<std::size_t>(std::max(neighbours, kScreenAtLeast));
  for (std::size_t i = 0; i < regions.size(); ++i) {
    if (!has[i]) continue;
    std::vector<std::pair<double, std::size_t>> near;
    for (std::size_t j = 0; j < regions.size(); ++j)
      if (j != i && has[j]) near.emplace_back(std::hypot(stats[j].cx - stats[i].cx, stats[j].cy - stats[i].cy), j);
    if (near.size() < kScreenMin) continue;
    const auto take = std::min(screen_n, near.size());
    std::partial_sort(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(take), near.end());
    std::vector<double> others;
    double nu = dof[i];
    for (std::size_t k = 0; k < take; ++k) {
      others.push_back(level[near[k].second]);
      nu = std::min(nu, dof[near[k].second]);
    }
    // The fewest degrees of freedom among them (rounded down): the widest tail, so a clean region is left out less.
    const int v = std::max(1, static_cast<int>(std::floor(nu)));
    const auto mid = others.begin() + static_cast<std::ptrdiff_t>(others.size() / 2);
    std::nth_element(others.begin(), mid, others.end());
    double median = *mid;
    if (others.size() % 2 == 0) median = 0.5 * (median + *std::max_element(others.begin(), mid));
    const double sigma2 = median / (chi_square_quantile(0.5, v) / v);
    // Neighbours without noise (an exact or clipped region) say nothing of this one's: judging it by its own few
    // degrees of freedom would cover too rarely, keeping it in their pool only widens theirs.
    if (!(sigma2 > 0)) continue;
    out.left_out[i] = level[i] > sigma2 * chi_square_quantile(kScreenP, v) / v;
  }

  // Pass 2: the shape with plain sums over the regions kept (the method of moments as it is unbiased), and each
  // region's relative per-pixel covariance pooled over its `neighbours` nearest kept regions; a region left out is
  // judged by its own spread (its mean is as uncertain as its own residuals say, or it is the scene's texture, which
  // a wider band there only makes conservative).
  std::vector<double> kept(regions.size(), 0.0);
  for (std::size_t j = 0; j < regions.size(); ++j) kept[j] = stats[j].usable && !out.left_out[j] ? 1.0 : 0.0;
  const Eigen::VectorXd rho = correlation(kept);
  for (std::size_t e = 0; e < lags.size(); ++e)
    if (lags[e] == Lag{1, 0}) out.lag1_correlation = rho[static_cast<Eigen::Index>(e)];
  std::vector<double> exp_e(regions.size(), 0.0);
  std::vector<std::size_t> pooled;
  for (std::size_t j = 0; j < regions.size(); ++j) {
    exp_e[j] = expected(j, rho);
    if (kept[j] > 0 && exp_e[j] > 0) pooled.push_back(j);
  }
  if (pooled.empty()) return out;
  out.covariance.resize(regions.size());
  for (std::size_t i = 0; i < regions.size(); ++i) {
    const auto& st = stats[i];
    Eigen::MatrixXd s = Eigen::MatrixXd::Zero(dim, dim);
    double e = 0;
    if (out.left_out[i] && exp_e[i] > 0) {
      s = st.s;
      e = exp_e[i];
    } else {
      std::vector<std::pair<double, std::size_t>> near;
      for (const std::size_t j : pooled) near.emplace_back(std::hypot(stats[j].cx - st.cx, stats[j].cy - st.cy), j);
      const auto take = std::min<std::size_t>(static_cast<std::size_t>(neighbours), near.size());
      std::partial_sort(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(take), near.end());
      for (std::size_t k = 0; k < take; ++k) {
        s += stats[near[k].second].s;
        e += exp_e[near[k].second];
      }
    }
    const PixelRect& g = regions[i];
    const double n = static_cast<double>(g.w) * g.h;
    double v = n;
    for (std::size_t d = 1; d < lags.size(); ++d) v += 2 * rho[static_cast<Eigen::Index>(d)] * pairs(lags[d], g.w, g.h);
    // Never below white noise's 1/N: a negative correlation estimated from few pixels is not a reason to believe the
    // mean better than independent pixels would make it.
    v = std::max(v, n) / (n * n);
    Eigen::VectorXd scale = st.scale;  // relative to the whole region's mean, where the window is only its centre
    if (g.w > kWindow || g.h > kWindow) {
      const Eigen::VectorXd whole = to * region_mean(r, g);
      scale = whole.cwiseAbs().cwiseMax(1e-3 * whole.norm());
    }
    out.covariance[i] = scale.asDiagonal() * (s / e) * scale.asDiagonal() * v;
  }
  return out;
}

}  // namespace colorlab::verify::detail
