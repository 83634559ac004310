#include "colorlab/analysis/frame_accumulator.hpp"

#include <cmath>
#include <string>

#include "colorlab/core/error.hpp"

namespace colorlab::analysis {

FrameAccumulator::FrameAccumulator(std::size_t width, std::size_t height)
    : width_(width), height_(height), sum_(width * height, 0), sumsq_(width * height, 0) {
  if (width == 0 || height == 0)
    throw Error(ErrorClass::bad_parameter, "frame accumulator needs a non-empty frame size");
}

void FrameAccumulator::add(std::span<const std::uint16_t> frame) {
  if (frame.size() != sum_.size())
    throw Error(ErrorClass::bad_data, "frame " + std::to_string(frames_ + 1) + " has " + std::to_string(frame.size()) +
                                          " pixels, expected " + std::to_string(width_) + "x" + std::to_string(height_));
  if (frames_ >= 65537)
    throw Error(ErrorClass::bad_parameter, "frame accumulator is full (65537 frames); 32-bit sums would overflow");
  const std::size_t n = sum_.size();
  std::uint32_t* __restrict s = sum_.data();
  std::uint64_t* __restrict q = sumsq_.data();
  const std::uint16_t* __restrict f = frame.data();
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t v = f[i];
    s[i] += v;
    q[i] += static_cast<std::uint64_t>(v * v);
  }
  ++frames_;
}

std::vector<float> FrameAccumulator::mean() const {
  std::vector<float> m(sum_.size(), 0.0f);
  if (frames_ == 0) return m;
  const double inv = 1.0 / static_cast<double>(frames_);
  for (std::size_t i = 0; i < m.size(); ++i) m[i] = static_cast<float>(sum_[i] * inv);
  return m;
}

std::vector<float> FrameAccumulator::stddev() const {
  std::vector<float> sd(sum_.size(), 0.0f);
  if (frames_ < 2) return sd;
  const double n = static_cast<double>(frames_);
  for (std::size_t i = 0; i < sd.size(); ++i) {
    // x87 long double keeps 64 mantissa bits: n·Σx² − (Σx)² stays exact where double would cancel.
    const long double a = static_cast<long double>(sumsq_[i]) * static_cast<long double>(frames_);
    const long double b = static_cast<long double>(sum_[i]) * static_cast<long double>(sum_[i]);
    const double num = static_cast<double>(a - b);
    sd[i] = static_cast<float>(std::sqrt(num / (n * (n - 1))));
  }
  return sd;
}

void FrameAccumulator::reset() {
  std::fill(sum_.begin(), sum_.end(), 0u);
  std::fill(sumsq_.begin(), sumsq_.end(), 0ull);
  frames_ = 0;
}

}  // namespace colorlab::analysis
