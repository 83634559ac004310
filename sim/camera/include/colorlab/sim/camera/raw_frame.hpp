#pragma once
// One raw Bayer exposure as the sensor's ADC delivers it.
#include <cstdint>
#include <string>
#include <vector>

namespace colorlab::sim::camera {

struct CameraSettings {
  double f_number = 4.0;
  double shutter_s = 1.0 / 30.0;
  int iso = 100;
};

struct RawFrame {
  int width = 0;
  int height = 0;
  std::vector<std::uint16_t> pixels;  // row-major, 12-bit counts including the black level
  std::string cfa = "RGGB";           // colours of the top-left 2×2 block, row by row
  int black_level = 256;
  int white_level = 4095;
  std::uint64_t frame_index = 0;
  CameraSettings settings;

  std::uint16_t at(int x, int y) const { return pixels[static_cast<std::size_t>(y) * width + x]; }
};

// CFA colour (0 = R, 1 = G, 2 = B) of pixel (x, y) in an RGGB mosaic.
constexpr int rggb_channel(int x, int y) { return (y & 1) == 0 ? ((x & 1) == 0 ? 0 : 1) : ((x & 1) == 0 ? 1 : 2); }

}  // namespace colorlab::sim::camera
