#pragma once
// Charts for the locator tests: a flat chart image written by the test (exact patch colours), put into a
// photograph at a pose by ImageMagick's `-distort Perspective` (a tool that is not ours), with the truth of
// where every patch centre lands computed from the same four point pairs.
#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "colorlab/analysis/chart_layout.hpp"

namespace colorlab::analysis::testing {

using Quad4 = std::array<std::array<double, 2>, 4>;

struct FlatChart {
  int width = 0, height = 0;
  int margin = 20, pitch = 38, size = 30;            // pixels; size / pitch ≈ the layout's patch size
  std::vector<std::array<std::uint16_t, 3>> colour;  // per patch, layout order, 16-bit
  std::vector<std::uint16_t> rgb;                    // interleaved
  // Patch centre and grid corners in pixel-centre-at-integer coordinates of the flat image.
  double centre_x(const ChartLayout& L, int k) const { return margin + L.column[static_cast<std::size_t>(k)] * pitch + (size - 1) / 2.0; }
  double centre_y(const ChartLayout& L, int k) const { return margin + L.row[static_cast<std::size_t>(k)] * pitch + (size - 1) / 2.0; }
};

// Neutral patches at the layout's expected luminance (sRGB-like 1/2.2 encoding), the rest seeded random colours;
// black surround. noise_sigma in 16-bit counts.
inline FlatChart draw_flat_chart(const ChartLayout& L, std::uint64_t seed, double noise_sigma, int pitch = 38) {
  FlatChart f;
  f.pitch = pitch;
  f.size = static_cast<int>(std::lround(pitch * L.patch_size));
  f.margin = pitch / 2;
  f.width = 2 * f.margin + (L.columns - 1) * f.pitch + f.size;
  f.height = 2 * f.margin + (L.rows - 1) * f.pitch + f.size;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < L.size(); ++k) {
    const double y = L.expected_luminance[static_cast<std::size_t>(k)];
    const double lum = std::isfinite(y) ? y : 0.05 + 0.6 * u(rng);
    const double g = std::pow(lum, 1 / 2.2);
    const bool neutral = (L.type == ChartType::sg140 && std::isfinite(y)) ||
                         std::find(L.neutral_ramp.begin(), L.neutral_ramp.end(), k) != L.neutral_ramp.end();
    std::array<std::uint16_t, 3> c{};
    for (int ch = 0; ch < 3; ++ch) {
      const double v = neutral ? g : std::clamp(g * (0.7 + 0.6 * u(rng)), 0.02, 0.98);
      c[static_cast<std::size_t>(ch)] = static_cast<std::uint16_t>(std::lround(v * 255) * 257);  // 8-bit exact
    }
    f.colour.push_back(c);
  }
  const std::uint16_t surround = 12 * 257;
  f.rgb.assign(static_cast<std::size_t>(f.width) * f.height * 3, surround);
  for (int k = 0; k < L.size(); ++k) {
    const int x0 = f.margin + L.column[static_cast<std::size_t>(k)] * f.pitch, y0 = f.margin + L.row[static_cast<std::size_t>(k)] * f.pitch;
    for (int y = y0; y < y0 + f.size; ++y)
      for (int x = x0; x < x0 + f.size; ++x)
        for (int ch = 0; ch < 3; ++ch) f.rgb[(static_cast<std::size_t>(y) * f.width + x) * 3 + ch] = f.colour[static_cast<std::size_t>(k)][static_cast<std::size_t>(ch)];
  }
  std::normal_distribution<double> n(0.0, noise_sigma);
  if (noise_sigma > 0)
    for (auto& v : f.rgb) v = static_cast<std::uint16_t>(std::clamp(v + n(rng), 0.0, 65535.0));
  return f;
}

inline void write_ppm16(const std::filesystem::path& p, const FlatChart& f) {
  std::ofstream o(p, std::ios::binary);
  o << "P6\n"
    << f.width << " " << f.height << "\n65535\n";
  for (std::uint16_t v : f.rgb) {
    const char b[2] = {static_cast<char>(v >> 8), static_cast<char>(v & 0xFF)};
    o.write(b, 2);
  }
}

// The projective map ImageMagick's 4-point Perspective distortion applies (image coordinates, pixel centres at +0.5).
inline Eigen::Matrix3d perspective(const std::array<std::array<double, 2>, 4>& src, const std::array<std::array<double, 2>, 4>& dst) {
  Eigen::Matrix<double, 8, 8> A;
  Eigen::Matrix<double, 8, 1> b;
  for (int i = 0; i < 4; ++i) {
    const double x = src[static_cast<std::size_t>(i)][0], y = src[static_cast<std::size_t>(i)][1];
    const double u = dst[static_cast<std::size_t>(i)][0], v = dst[static_cast<std::size_t>(i)][1];
    A.row(2 * i) << x, y, 1, 0, 0, 0, -u * x, -u * y;
    A.row(2 * i + 1) << 0, 0, 0, x, y, 1, -v * x, -v * y;
    b(2 * i) = u;
    b(2 * i + 1) = v;
  }
  const Eigen::Matrix<double, 8, 1> h = A.fullPivLu().solve(b);
  Eigen::Matrix3d H;
  H << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), 1;
  return H;
}

struct Posed {
  std::filesystem::path file;
  std::vector<std::array<double, 2>> centre;    // truth per patch, output pixel centres at integers
  std::array<std::array<double, 2>, 4> corner;  // grid corners in reading order
};

// dst: where the flat image's corners (TL, TR, BR, BL of the image) land in a out_w × out_h photograph.
// extra: more ImageMagick options applied before writing (e.g. "-depth 8", "-quality 92").
inline Posed pose_with_imagemagick(const ChartLayout& L, const FlatChart& f, const std::filesystem::path& dir, const std::string& name,
                                   const std::array<std::array<double, 2>, 4>& dst, int out_w, int out_h, const std::string& extra) {
  const std::filesystem::path flat = dir / (name + "-flat.ppm");
  write_ppm16(flat, f);
  const std::array<std::array<double, 2>, 4> src{{{0, 0}, {double(f.width), 0}, {double(f.width), double(f.height)}, {0, double(f.height)}}};
  std::ostringstream pts;
  for (int i = 0; i < 4; ++i)
    pts << src[static_cast<std::size_t>(i)][0] << "," << src[static_cast<std::size_t>(i)][1] << " " << dst[static_cast<std::size_t>(i)][0] << ","
        << dst[static_cast<std::size_t>(i)][1] << " ";
  Posed out;
  out.file = dir / name;
  std::ostringstream cmd;
  cmd << "convert " << flat << " -background 'rgb(150,140,130)' -virtual-pixel background -define distort:viewport=" << out_w << "x"
      << out_h << "+0+0 -distort Perspective '" << pts.str() << "' " << extra << " " << out.file << " 2>&1";
  if (std::system(cmd.str().c_str()) != 0) throw std::runtime_error("ImageMagick failed: " + cmd.str());
  const Eigen::Matrix3d H = perspective(src, dst);
  auto map = [&](double x, double y) -> std::array<double, 2> {
    const Eigen::Vector3d v = H * Eigen::Vector3d(x + 0.5, y + 0.5, 1);
    return {v(0) / v(2) - 0.5, v(1) / v(2) - 0.5};
  };
  for (int k = 0; k < L.size(); ++k) out.centre.push_back(map(f.centre_x(L, k), f.centre_y(L, k)));
  const double x0 = f.margin - 0.5, y0 = f.margin - 0.5;
  const double x1 = f.margin + (L.columns - 1) * f.pitch + f.size - 0.5, y1 = f.margin + (L.rows - 1) * f.pitch + f.size - 0.5;
  out.corner = {map(x0, y0), map(x1, y0), map(x1, y1), map(x0, y1)};
  return out;
}

}  // namespace colorlab::analysis::testing
