#pragma once
// The one frame type every camera delivers: undemosaiced sensor counts plus what is needed to
// interpret them (CFA layout, black and white levels, visible area). It is what `dcraw -D -4`
// writes, so DSLR files, GenICam buffers and simulated frames all reach the analysis code alike.
#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace colorlab::drivers::camera {

enum class CfaColor : std::uint8_t {
  red = 0,
  green = 1,
  blue = 2,
  none = 3
};

// Colour of each cell of the 2x2 repeat, indexed [row % 2][col % 2] in visible-area coordinates.
struct CfaPattern {
  std::array<std::array<CfaColor, 2>, 2> cell{};

  static CfaPattern rggb();
  static CfaPattern monochrome();  // every cell `none`
  bool is_mosaic() const { return cell[0][0] != CfaColor::none; }
  CfaColor at(std::size_t row, std::size_t col) const { return cell[row & 1U][col & 1U]; }
  std::string name() const;  // "RGGB", "GBRG", ..., "mono"
  friend bool operator==(const CfaPattern&, const CfaPattern&) = default;
};

// A borrowed view: `pixels` stays valid only for the duration of the call that hands it out.
// Coordinates in at()/row() are in the visible area; the full raw (with masked margins) is
// reachable through raw_width/raw_height and the margins.
struct RawImage {
  const std::uint16_t* pixels = nullptr;  // first pixel of the full raw, margins included
  std::size_t row_stride = 0;             // in pixels
  std::size_t raw_width = 0;
  std::size_t raw_height = 0;
  std::size_t left_margin = 0;
  std::size_t top_margin = 0;
  std::size_t width = 0;  // visible area
  std::size_t height = 0;
  CfaPattern cfa = CfaPattern::rggb();
  std::array<std::uint16_t, 4> black_level{};  // per CFA cell, [row%2 * 2 + col%2]
  std::uint16_t white_level = 0;               // largest valid count (saturation)
  std::uint32_t bits_per_sample = 16;
  std::chrono::system_clock::time_point timestamp{};
  std::uint64_t frame_index = 0;  // position in the capture series, 0-based

  std::uint16_t at(std::size_t x, std::size_t y) const {
    return pixels[(y + top_margin) * row_stride + x + left_margin];
  }
  std::span<const std::uint16_t> row(std::size_t y) const {
    return {pixels + (y + top_margin) * row_stride + left_margin, width};
  }
  // The whole raw (margins included) as one contiguous block, for frame accumulators;
  // empty when rows are padded (row_stride > raw_width).
  std::span<const std::uint16_t> contiguous() const {
    if (row_stride != raw_width) return {};
    return {pixels, raw_width * raw_height};
  }
  std::uint16_t black_at(std::size_t x, std::size_t y) const {
    return black_level[(y & 1U) * 2 + (x & 1U)];
  }
};

// An owning frame, for code that must keep pixels beyond a sink call (queues, tests, fixtures).
struct OwnedRawImage {
  std::vector<std::uint16_t> storage;
  RawImage meta;  // meta.pixels is re-pointed at storage by view()

  RawImage view() const {
    RawImage v = meta;
    v.pixels = storage.data();
    return v;
  }
  // Deep copy of a borrowed view (visible area and margins kept as they are).
  static OwnedRawImage copy_of(const RawImage& image);
};

}  // namespace colorlab::drivers::camera
