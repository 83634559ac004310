#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <string>
#include <thread>

#include "colorlab/core/error.hpp"
#include "colorlab/sim/camera/processed.hpp"

namespace colorlab::sim::camera {
namespace {

// XYZ (D65) → linear Adobe RGB (1998), from the Adobe RGB (1998) specification's primaries and D65 white.
const Eigen::Matrix3d kXyzToAdobe = (Eigen::Matrix3d() << 2.04159, -0.56501, -0.34473,  //
                                     -0.96924, 1.87597, 0.04156,                        //
                                     0.01344, -0.11836, 1.01517)
                                        .finished();
constexpr double kAdobeGamma = 563.0 / 256.0;
constexpr double kPleasingSaturation = 1.06;  // what makes the built-in matrix "imperfect"

Eigen::Matrix3d to_matrix(const std::array<double, 9>& a) {
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) = a[static_cast<std::size_t>(r * 3 + c)];
  return m;
}

}  // namespace

std::array<double, 9> builtin_camera_to_xyz(const CameraModel& camera) {
  const Eigen::Matrix3d xyz_to_cam = to_matrix(camera.xyz_to_camera_d65());
  // White-balanced camera RGB (D65 white → 1,1,1) → XYZ.
  const Eigen::Vector3d d65(0.95047, 1.0, 1.08883);
  const Eigen::Vector3d neutral = xyz_to_cam * d65;
  Eigen::Matrix3d m = xyz_to_cam.inverse() * neutral.asDiagonal();
  // Boost saturation around the neutral axis in camera space, keeping white fixed.
  const Eigen::Matrix3d grey = Eigen::Matrix3d::Constant(1.0 / 3.0);
  m = m * (kPleasingSaturation * Eigen::Matrix3d::Identity() + (1.0 - kPleasingSaturation) * grey);
  std::array<double, 9> out{};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out[static_cast<std::size_t>(r * 3 + c)] = m(r, c);
  return out;
}

RgbImage develop(const RawFrame& frame, const CameraModel& camera, const DevelopSettings& settings) {
  if (frame.cfa != "RGGB") throw Error(ErrorClass::bad_parameter, "develop: only RGGB mosaics, got " + frame.cfa);
  if (frame.width < 4 || frame.height < 4 || frame.pixels.size() != std::size_t(frame.width) * std::size_t(frame.height))
    throw Error(ErrorClass::bad_parameter, "develop: frame size does not match its pixels");
  const std::array<double, 3> neutral = settings.neutral ? *settings.neutral : camera.as_shot_neutral();
  for (double n : neutral)
    if (!(n > 0)) throw Error(ErrorClass::bad_parameter, "develop: white-balance neutral must be positive");
  const Eigen::Matrix3d to_rgb = kXyzToAdobe * to_matrix(builtin_camera_to_xyz(camera));
  const double scale = settings.exposure / double(frame.white_level - frame.black_level);
  const std::array<double, 3> wb{scale / neutral[0], scale / neutral[1], scale / neutral[2]};
  const int W = frame.width, H = frame.height;

  // Linear, black-subtracted, white-balanced sample at (x, y), clamped to the frame.
  auto lin = [&](int x, int y) {
    x = std::clamp(x, 0, W - 1);
    y = std::clamp(y, 0, H - 1);
    return (double(frame.pixels[std::size_t(y) * W + x]) - frame.black_level) * wb[static_cast<std::size_t>(rggb_channel(x, y))];
  };
  // A 64 Ki-entry gamma table for the encoding (input quantised to 1/65535, far below 16-bit output steps).
  std::vector<std::uint16_t> gamma(65536);
  for (std::size_t i = 0; i < gamma.size(); ++i)
    gamma[i] = static_cast<std::uint16_t>(std::lround(65535.0 * std::pow(double(i) / 65535.0, 1.0 / kAdobeGamma)));

  RgbImage out{W, H, std::vector<std::uint16_t>(std::size_t(W) * std::size_t(H) * 3)};
  auto rows = [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < W; ++x) {
        // Bilinear demosaic: the pixel's own colour plus the mean of the nearest neighbours of the others.
        double rgb[3];
        const int c = rggb_channel(x, y);
        const double self = lin(x, y);
        const double cross = (lin(x - 1, y) + lin(x + 1, y) + lin(x, y - 1) + lin(x, y + 1)) / 4;
        const double diag = (lin(x - 1, y - 1) + lin(x + 1, y - 1) + lin(x - 1, y + 1) + lin(x + 1, y + 1)) / 4;
        if (c == 1) {
          const double horiz = (lin(x - 1, y) + lin(x + 1, y)) / 2, vert = (lin(x, y - 1) + lin(x, y + 1)) / 2;
          const bool red_row = (y & 1) == 0;
          rgb[0] = red_row ? horiz : vert;
          rgb[1] = self;
          rgb[2] = red_row ? vert : horiz;
        } else {
          rgb[c] = self;
          rgb[1] = cross;
          rgb[2 - c] = diag;
        }
        const Eigen::Vector3d v = to_rgb * Eigen::Vector3d(rgb[0], rgb[1], rgb[2]);
        std::uint16_t* o = &out.rgb[(std::size_t(y) * W + x) * 3];
        for (int k = 0; k < 3; ++k)
          o[k] = gamma[static_cast<std::size_t>(std::lround(std::clamp(v[k], 0.0, 1.0) * 65535.0))];
      }
  };
  std::thread second(rows, H / 2, H);
  rows(0, H / 2);
  second.join();
  return out;
}

}  // namespace colorlab::sim::camera
