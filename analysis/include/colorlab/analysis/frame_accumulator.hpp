#pragma once
// Streaming per-pixel mean and standard deviation over any number of 16-bit frames, holding none of them.
#include <cstdint>
#include <span>
#include <vector>

namespace colorlab::analysis {

class FrameAccumulator {
 public:
  FrameAccumulator(std::size_t width, std::size_t height);

  // Throws Error(bad_data) for a wrong frame size, Error(bad_parameter) before the u32 sums could overflow
  // (65 537 frames of full-scale 16-bit data).
  void add(std::span<const std::uint16_t> frame);

  std::size_t frames() const { return frames_; }
  std::size_t width() const { return width_; }
  std::size_t height() const { return height_; }
  std::vector<float> mean() const;
  // Sample standard deviation per pixel (n − 1); zeros for a single frame.
  std::vector<float> stddev() const;
  void reset();

 private:
  std::size_t width_, height_, frames_ = 0;
  std::vector<std::uint32_t> sum_;
  std::vector<std::uint64_t> sumsq_;
};

}  // namespace colorlab::analysis
