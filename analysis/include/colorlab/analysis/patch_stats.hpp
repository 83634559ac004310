#pragma once
// Patch values from images: the dissertation's robust value (§6.1.2), CFA channels, defect maps, noise vs averaging.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "colorlab/analysis/statistics.hpp"

namespace colorlab::analysis {

// A single-channel image (any numeric sample stored as float). stride in samples.
struct ImageView {
  const float* data = nullptr;
  std::size_t width = 0, height = 0, stride = 0;
  float at(std::size_t x, std::size_t y) const { return data[y * stride + x]; }
};

struct Rect {
  std::size_t x = 0, y = 0, width = 0, height = 0;
};

// 1 = defective (excluded), 0 = good; same size as the image.
struct PixelMask {
  std::size_t width = 0, height = 0;
  std::vector<std::uint8_t> bad;
  bool is_bad(std::size_t x, std::size_t y) const { return !bad.empty() && bad[y * width + x] != 0; }
  std::size_t count() const;
};

struct RobustOptions {
  int bit_depth = 8;
  // Half-width of the accepted band around the median; default 5 counts at 8 bit, scaled by 2^(bits−8).
  std::optional<double> k;
  double effective_k() const;
};

struct PatchValue {
  double value = 0;  // mean of pixels within ±k of the median
  double median = 0;
  std::size_t used = 0, good = 0, total = 0;
};

// Throws Error(bad_data) if the region leaves the image, is empty, or has no good pixel.
PatchValue robust_patch_value(const ImageView& image, const Rect& region, const RobustOptions& options = {},
                              const PixelMask* defects = nullptr);

enum class CfaPattern {
  rggb,
  bggr,
  grbg,
  gbrg
};

// Robust value of each colour of a Bayer mosaic within the region: R, G (both greens), B.
std::array<PatchValue, 3> cfa_patch_values(const ImageView& raw, const Rect& region, CfaPattern pattern,
                                           const RobustOptions& options = {}, const PixelMask* defects = nullptr);

struct DefectOptions {
  double hot_sigma = 6.0;        // dark-frame pixel above median + hot_sigma · robust σ is hot
  double dead_fraction = 0.5;    // flat-frame pixel below this fraction of the median is dead
  double bright_fraction = 1.5;  // ... or above this multiple is stuck bright
};

// Hot pixels from a (mean) dark frame, dead/stuck ones from a (mean) flat field; either may be omitted (data null).
PixelMask defect_map(const ImageView& dark, const ImageView& flat, const DefectOptions& options = {});

// Table 2: for each subset size N (first N frames averaged), the per-patch standard deviation of the averaged
// pixels, summarised over patches. frames hold one channel each.
inline constexpr std::array<std::size_t, 6> kTable2Subsets{1, 2, 4, 8, 16, 25};

struct NoiseRow {
  std::size_t frames = 0;
  std::vector<double> patch_stdev;  // one per region
  Summary summary;                  // median and mean are Table 2's rows
};
std::vector<NoiseRow> noise_vs_averaging(std::span<const ImageView> frames, std::span<const Rect> regions,
                                         std::span<const std::size_t> subset_sizes = kTable2Subsets,
                                         const PixelMask* defects = nullptr);

}  // namespace colorlab::analysis
