#pragma once
// A photograph as the chart locator reads it: 8- or 16-bit samples, grey, RGB or a raw CFA mosaic.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include "colorlab/analysis/patch_stats.hpp"

namespace colorlab::analysis {

enum class SampleType {
  u8,
  u16
};

// A view of pixel data owned elsewhere. channels = 1 (grey or CFA) or 3 (interleaved R, G, B).
struct PhotoView {
  const void* data = nullptr;
  int width = 0, height = 0;
  int channels = 1;
  SampleType type = SampleType::u16;
  std::size_t stride = 0;         // samples per row; 0 = width · channels
  int bit_depth = 0;              // significant bits (12 for a 12-bit raw); 0 = 8 or 16 from the type
  double black_level = 0;         // subtracted for finding the chart (not from the reported values)
  std::optional<CfaPattern> cfa;  // set: a raw mosaic (channels = 1), sampled per CFA colour

  std::size_t row_stride() const { return stride ? stride : static_cast<std::size_t>(width) * channels; }
  int bits() const { return bit_depth > 0 ? bit_depth : (type == SampleType::u8 ? 8 : 16); }
};

// An image file read into memory.
struct Photo {
  int width = 0, height = 0, channels = 1;
  SampleType type = SampleType::u16;
  std::vector<std::uint8_t> bytes;  // row-major, interleaved R, G, B (never BGR)
  PhotoView view() const;
};

// TIFF (8/16 bit), JPEG, PNG, PGM/PPM via OpenCV. Colour images come back as RGB, grey ones as one channel.
// Throws Error(not_found) for a missing file, Error(bad_data) for one OpenCV cannot decode.
Photo read_photo(const std::filesystem::path& path);

}  // namespace colorlab::analysis
