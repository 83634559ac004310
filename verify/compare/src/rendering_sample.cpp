#include "rendering_sample.hpp"

#include <algorithm>
#include <string>

#include "colorlab/analysis/standard_data.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::verify::detail {

Eigen::VectorXd region_mean(const Rendering& r, const PixelRect& g) {
  if (g.w <= 0 || g.h <= 0 || g.x < 0 || g.y < 0 || g.x + g.w > r.width || g.y + g.h > r.height)
    throw Error(ErrorClass::bad_data,
                "region " + std::to_string(g.x) + "," + std::to_string(g.y) + " " + std::to_string(g.w) + "x" +
                    std::to_string(g.h) + " is not inside the " + std::to_string(r.width) + "x" +
                    std::to_string(r.height) + " rendering",
                "the rendering must show the chart and floor where the measured scene's camera saw them");
  const int n = r.channels();
  if (r.pixels.size() != static_cast<std::size_t>(r.width) * static_cast<std::size_t>(r.height) * static_cast<std::size_t>(n))
    throw Error(ErrorClass::bad_data, "the rendering's pixel buffer does not match its size and channels");
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(n);
  for (int y = g.y; y < g.y + g.h; ++y)
    for (int x = g.x; x < g.x + g.w; ++x) {
      const float* p = r.pixel(x, y);
      for (int c = 0; c < n; ++c) sum[c] += p[c];
    }
  return sum / (static_cast<double>(g.w) * g.h);
}

Eigen::VectorXd shifted_mean(const Rendering& r, const PixelRect& g, int dx, int dy) {
  PixelRect s = g;
  s.x = std::clamp(g.x + dx, 0, std::max(0, r.width - g.w));
  s.y = std::clamp(g.y + dy, 0, std::max(0, r.height - g.h));
  return region_mean(r, s);
}

std::vector<double> band_widths(const std::vector<double>& c) {
  std::vector<double> w(c.size(), 0.0);
  if (c.size() == 1) return {1.0};  // one band: radiance taken as already integrated
  for (std::size_t i = 0; i < c.size(); ++i) {
    const double lo = i == 0 ? c[0] - 0.5 * (c[1] - c[0]) : 0.5 * (c[i - 1] + c[i]);
    const double hi = i + 1 == c.size() ? c[i] + 0.5 * (c[i] - c[i - 1]) : 0.5 * (c[i] + c[i + 1]);
    w[i] = hi - lo;
  }
  return w;
}

Eigen::Matrix3d rgb_to_xyz_matrix(const Chromaticities& c) {
  Eigen::Matrix3d p;
  for (int i = 0; i < 3; ++i) {
    const double x = c[i][0], y = c[i][1];
    p.col(i) << x / y, 1.0, (1 - x - y) / y;
  }
  const double wx = c[3][0], wy = c[3][1];
  const Eigen::Vector3d w(wx / wy, 1.0, (1 - wx - wy) / wy);
  const Eigen::Vector3d s = p.fullPivLu().solve(w);
  return p * s.asDiagonal();
}

ToXyz::ToXyz(const Rendering& r) {
  switch (r.encoding) {
    case Encoding::xyz:
      m_ = Eigen::Matrix3d::Identity() * r.white_luminance_cd_m2.value_or(1.0);
      break;
    case Encoding::rgb: {
      Chromaticities c = r.chromaticities;
      if (!r.chromaticities_from_file) c = {{{0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}, {0.3127, 0.3290}}};
      // OpenEXR's whiteLuminance makes RGB (1,1,1) that many cd/m², as renderings/io's to_xyz reads it.
      m_ = rgb_to_xyz_matrix(c) * r.white_luminance_cd_m2.value_or(1.0);
      break;
    }
    case Encoding::spectral: {
      const auto& wl = r.wavelengths_nm;
      if (wl.empty()) throw Error(ErrorClass::bad_data, "a spectral rendering without wavelengths");
      // Read once per process: colord's table does not change while colorlab runs.
      static const analysis::SpectralSet obs = analysis::load_observer(analysis::Observer::cie1931_2deg);
      const auto w = band_widths(wl);
      m_.resize(3, static_cast<Eigen::Index>(wl.size()));
      for (std::size_t i = 0; i < wl.size(); ++i) {
        // Linear interpolation of the observer at the band centre; zero outside its table.
        const auto& g = obs.wavelengths;
        double cmf[3] = {0, 0, 0};
        if (wl[i] >= g.front() && wl[i] <= g.back()) {
          const auto it = std::upper_bound(g.begin(), g.end(), wl[i]);
          const std::size_t hi = std::min<std::size_t>(static_cast<std::size_t>(it - g.begin()), g.size() - 1);
          const std::size_t lo = hi == 0 ? 0 : hi - 1;
          const double t = g[hi] == g[lo] ? 0 : (wl[i] - g[lo]) / (g[hi] - g[lo]);
          for (int k = 0; k < 3; ++k)
            cmf[k] = (1 - t) * obs.values(k, static_cast<Eigen::Index>(lo)) + t * obs.values(k, static_cast<Eigen::Index>(hi));
        }
        for (int k = 0; k < 3; ++k) m_(k, static_cast<Eigen::Index>(i)) = 683.0 * cmf[k] * w[i];
      }
      break;
    }
  }
}

analysis::Xyz ToXyz::operator()(const Eigen::VectorXd& ch) const {
  const Eigen::Vector3d v = m_ * ch;
  return {v[0], v[1], v[2]};
}

}  // namespace colorlab::verify::detail
