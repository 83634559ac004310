#include "speed_renderings.hpp"

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <vector>

#include "colorlab/analysis/chart_layout.hpp"
#include "colorlab/sim/clock.hpp"
#include "colorlab/sim/scene.hpp"
#include "colorlab/verify/rendering_xyz.hpp"

namespace colorlab::bench {

namespace {

constexpr int kBands = 36;
constexpr double kFlatToCdM2 = 683 * 106.857;  // a flat 1 W·m⁻²·sr⁻¹·nm⁻¹ over 380–730 nm, as luminance

float noise(std::uint64_t i) {
  std::uint32_t h = static_cast<std::uint32_t>(i ^ (i >> 32));
  h ^= h >> 16;
  h *= 0x7feb352dU;
  h ^= h >> 15;
  h *= 0x846ca68bU;
  h ^= h >> 16;
  return static_cast<float>(h) / 4294967296.0f - 0.5f;
}

// One surface's value in the rendering's channels, from its spectral radiance on the 36-band grid.
std::vector<double> channels_of(verify::Encoding e, const std::vector<double>& radiance) {
  if (e == verify::Encoding::spectral) return radiance;
  static const auto w = verify::band_cmf_weights([] {
    std::vector<double> nm;
    for (int b = 0; b < kBands; ++b) nm.push_back(380.0 + 10.0 * b);
    return nm;
  }());
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  for (int b = 0; b < kBands; ++b)
    for (int c = 0; c < 3; ++c) xyz[c] += 683.0 * w[static_cast<std::size_t>(b)][static_cast<std::size_t>(c)] * radiance[static_cast<std::size_t>(b)];
  if (e == verify::Encoding::xyz) return {xyz[0], xyz[1], xyz[2]};
  const auto m = verify::rgb_to_xyz_matrix(verify::rec709_chromaticities());
  Eigen::Matrix3d to_xyz;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) to_xyz(r, c) = m[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)];
  const Eigen::Vector3d rgb = to_xyz.inverse() * xyz;
  return {rgb[0], rgb[1], rgb[2]};
}

std::vector<double> on_grid(const sim::Spectrum& s) {
  std::vector<double> v;
  for (int b = 0; b < kBands; ++b) v.push_back(s.at(380.0 + 10.0 * b));
  return v;
}

}  // namespace

verify::Rendering chart_and_floor(verify::Encoding e, int w, int h) {
  verify::Rendering r;
  r.encoding = e;
  r.width = w;
  r.height = h;
  if (e == verify::Encoding::spectral) {
    r.units = "W.m^-2.sr^-1.nm^-1";
    for (int b = 0; b < kBands; ++b) r.wavelengths_nm.push_back(380.0 + 10.0 * b);
  } else if (e == verify::Encoding::rgb) {
    r.chromaticities = verify::rec709_chromaticities();
    r.chromaticities_from_file = true;
  }
  const int c = r.channels();
  r.pixels.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * static_cast<std::size_t>(c));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double u = double(x) / w, v = double(y) / h;
      const double lum = 150 + 100 * std::sin(3 * u) * std::cos(2 * v);
      const double base = e == verify::Encoding::spectral ? lum / kFlatToCdM2 : lum;
      for (int k = 0; k < c; ++k) {
        const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)) * static_cast<std::size_t>(c) +
                              static_cast<std::size_t>(k);
        r.pixels[i] = static_cast<float>(base * (1.0 + 0.01 * noise(i)));
      }
    }

  // The embedded lab's chart (its default SceneConfig: the chart does not depend on the daemon's seed) under D65.
  sim::SceneConfig config;
  sim::Scene scene(config, std::make_shared<sim::SimClock>(1.0));
  scene.set_lamp(sim::Lamp::d65, true);
  scene.set_dimmer(100);
  const auto& layout = analysis::chart_layout(analysis::ChartType::sg140);
  const int pitch = static_cast<int>(0.6 * w / layout.columns), side = pitch * 15 / 19;
  const int x0 = (w - layout.columns * pitch) / 2, y0 = (h - layout.rows * pitch) / 2;
  auto fill = [&](int xa, int ya, int xb, int yb, const std::vector<double>& value) {
    for (int y = ya; y < yb; ++y)
      for (int x = xa; x < xb; ++x)
        for (int k = 0; k < c; ++k) {
          const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)) * static_cast<std::size_t>(c) +
                                static_cast<std::size_t>(k);
          r.pixels[i] = static_cast<float>(value[static_cast<std::size_t>(k)] * (1.0 + 0.01 * noise(i)));
        }
  };
  // A near-black board half a pitch around the grid, so the SG's black border patches keep edges of their own.
  const sim::Spectrum board{380, 10, std::vector<double>(kBands, 0.005)};
  fill(x0 - pitch / 2, y0 - pitch / 2, x0 + layout.columns * pitch + pitch / 2, y0 + layout.rows * pitch + pitch / 2,
       channels_of(e, on_grid(scene.spectral_radiance(config.chart_center_x_mm, config.chart_center_y_mm, board))));
  for (int i = 0; i < layout.size(); ++i) {
    const auto idx = scene.chart().index_of(layout.ids[static_cast<std::size_t>(i)]);
    if (!idx) throw std::runtime_error("the simulator's chart has no patch " + layout.ids[static_cast<std::size_t>(i)]);
    const auto& p = scene.chart().patches[static_cast<std::size_t>(*idx)];
    const auto [fx, fy] = scene.patch_floor_position_mm(*idx);
    const int px = x0 + layout.column[static_cast<std::size_t>(i)] * pitch + (pitch - side) / 2;
    const int py = y0 + layout.row[static_cast<std::size_t>(i)] * pitch + (pitch - side) / 2;
    fill(px, py, px + side, py + side, channels_of(e, on_grid(scene.spectral_radiance(fx, fy, p.reflectance))));
  }
  return r;
}

}  // namespace colorlab::bench
