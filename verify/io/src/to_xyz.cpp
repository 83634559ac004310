#include <algorithm>
#include <cmath>
#include <thread>

#include "colorlab/analysis/spectral.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/verify/rendering_xyz.hpp"

namespace colorlab::verify {

namespace {

constexpr double kKm = 683.0;  // lm/W, the maximum luminous efficacy that defines the candela

// Rows [0, height) in one chunk per core; each pixel's XYZ depends on that pixel only.
template <class F>
void for_rows(int height, F&& f) {
  const int threads = std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1, 16);
  if (threads == 1 || height < 64) return f(0, height);
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) {
    const int y0 = height * t / threads, y1 = height * (t + 1) / threads;
    pool.emplace_back([&f, y0, y1] { f(y0, y1); });
  }
  for (auto& th : pool) th.join();
}

}  // namespace

Matrix3 rgb_to_xyz_matrix(const Chromaticities& c) {
  for (const auto& p : c)
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]))
      throw Error(ErrorClass::bad_data, "chromaticities must be finite", "the file's chromaticities attribute is corrupt");
  if (!(c[3][1] > 0))
    throw Error(ErrorClass::bad_data, "the white's chromaticity y must be positive", "the file's chromaticities attribute is corrupt");
  // Columns: each primary as (x, y, z) — any scale; OpenEXR's XYZ convention puts blue at (0, 0), so not Y = 1.
  Matrix3 P{};
  for (int k = 0; k < 3; ++k) {
    P[0][k] = c[k][0];
    P[1][k] = c[k][1];
    P[2][k] = 1.0 - c[k][0] - c[k][1];
  }
  const double W[3] = {c[3][0] / c[3][1], 1.0, (1.0 - c[3][0] - c[3][1]) / c[3][1]};
  // Solve P · S = W (Cramer's rule) so the primaries scaled by S add up to the white with Y = 1.
  auto det = [](const Matrix3& m) {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  };
  const double d = det(P);
  if (std::abs(d) < 1e-9)
    throw Error(ErrorClass::bad_data, "chromaticities: the three primaries are collinear, no RGB space spans XYZ",
                "the file's chromaticities attribute is corrupt");
  Matrix3 M{};
  for (int k = 0; k < 3; ++k) {
    Matrix3 Pk = P;
    for (int r = 0; r < 3; ++r) Pk[r][k] = W[r];
    const double s = det(Pk) / d;
    for (int r = 0; r < 3; ++r) M[r][k] = P[r][k] * s;
  }
  return M;
}

std::vector<std::array<double, 3>> band_cmf_weights(const std::vector<double>& wl, analysis::Observer observer) {
  const std::vector<double> edges = band_edges_nm(wl);
  const analysis::SpectralSet obs = analysis::load_observer(observer);
  const double lo = obs.wavelengths.front(), hi = obs.wavelengths.back();
  // Midpoint rule at ≤ 0.1 nm inside each box: the CMFs are smooth, so this is exact to far below float precision.
  std::vector<double> points;
  std::vector<std::size_t> band_of;
  std::vector<double> step_of;
  for (std::size_t b = 0; b + 1 < edges.size(); ++b) {
    const double a = std::max(edges[b], lo), z = std::min(edges[b + 1], hi);
    if (!(z > a)) continue;  // a band wholly outside the observer's range adds nothing
    const auto n = static_cast<std::size_t>(std::ceil((z - a) / 0.1));
    const double h = (z - a) / static_cast<double>(n);
    for (std::size_t k = 0; k < n; ++k) {
      points.push_back(a + (static_cast<double>(k) + 0.5) * h);
      band_of.push_back(b);
      step_of.push_back(h);
    }
  }
  std::vector<std::array<double, 3>> w(wl.size(), {0.0, 0.0, 0.0});
  if (points.empty()) return w;
  const Eigen::MatrixXd cmf =
      obs.values * analysis::resampling_matrix(obs.wavelengths, points, analysis::Interpolation::cubic_spline).transpose();
  for (std::size_t i = 0; i < points.size(); ++i)
    for (int k = 0; k < 3; ++k) w[band_of[i]][k] += std::max(0.0, cmf(k, static_cast<Eigen::Index>(i))) * step_of[i];
  return w;
}

Rendering to_xyz(const Rendering& im, analysis::Observer observer) {
  const std::size_t n = static_cast<std::size_t>(im.width) * static_cast<std::size_t>(im.height);
  const std::size_t c = static_cast<std::size_t>(im.channels());
  if (im.pixels.size() != n * c)
    throw Error(ErrorClass::bad_parameter, "rendering has " + std::to_string(im.pixels.size()) + " floats for " +
                                               std::to_string(im.width) + " x " + std::to_string(im.height) + " x " +
                                               std::to_string(c));
  Rendering out;
  out.encoding = Encoding::xyz;
  out.width = im.width;
  out.height = im.height;
  out.source_format = im.source_format;
  out.pixels.resize(n * 3);
  std::array<std::array<float, 3>, 3> m3{};
  std::vector<std::array<float, 3>> wb;
  switch (im.encoding) {
    case Encoding::spectral: {
      if (im.reflective)
        throw Error(ErrorClass::unsupported, "a reflective spectral image has no luminance without a light",
                    "render the scene's radiance (the S0 layer) for verification");
      for (const auto& w : band_cmf_weights(im.wavelengths_nm, observer))
        wb.push_back({static_cast<float>(kKm * w[0]), static_cast<float>(kKm * w[1]), static_cast<float>(kKm * w[2])});
      out.units = "cd/m^2";
      break;
    }
    case Encoding::rgb: {
      const Matrix3 m = rgb_to_xyz_matrix(im.chromaticities);
      const double s = im.white_luminance_cd_m2.value_or(1.0);
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) m3[r][k] = static_cast<float>(m[r][k] * s);
      out.units = im.white_luminance_cd_m2 ? "cd/m^2" : "";
      break;
    }
    case Encoding::xyz: {
      const double s = im.white_luminance_cd_m2.value_or(1.0);
      for (int r = 0; r < 3; ++r) m3[r][r] = static_cast<float>(s);
      out.units = im.white_luminance_cd_m2 ? "cd/m^2" : im.units;
      break;
    }
  }
  const float* src = im.pixels.data();
  float* dst = out.pixels.data();
  const std::size_t w = static_cast<std::size_t>(im.width);
  for_rows(im.height, [&](int y0, int y1) {
    for (std::size_t p = static_cast<std::size_t>(y0) * w; p < static_cast<std::size_t>(y1) * w; ++p) {
      const float* s = src + p * c;
      float X = 0, Y = 0, Z = 0;
      if (im.encoding == Encoding::spectral) {
        for (std::size_t b = 0; b < c; ++b) {
          X += wb[b][0] * s[b];
          Y += wb[b][1] * s[b];
          Z += wb[b][2] * s[b];
        }
      } else {
        X = m3[0][0] * s[0] + m3[0][1] * s[1] + m3[0][2] * s[2];
        Y = m3[1][0] * s[0] + m3[1][1] * s[1] + m3[1][2] * s[2];
        Z = m3[2][0] * s[0] + m3[2][1] * s[1] + m3[2][2] * s[2];
      }
      dst[p * 3] = X;
      dst[p * 3 + 1] = Y;
      dst[p * 3 + 2] = Z;
    }
  });
  return out;
}

}  // namespace colorlab::verify
