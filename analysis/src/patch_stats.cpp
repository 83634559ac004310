#include "colorlab/analysis/patch_stats.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "colorlab/core/error.hpp"

namespace colorlab::analysis {

namespace {
std::string describe(const Rect& r) {
  return "region x=" + std::to_string(r.x) + " y=" + std::to_string(r.y) + " " + std::to_string(r.width) + "x" +
         std::to_string(r.height);
}

void check_region(const ImageView& img, const Rect& r) {
  if (!img.data || img.width == 0 || img.height == 0) throw Error(ErrorClass::bad_data, "empty image");
  if (r.width == 0 || r.height == 0) throw Error(ErrorClass::bad_data, describe(r) + " is empty");
  if (r.x + r.width > img.width || r.y + r.height > img.height)
    throw Error(ErrorClass::bad_data, describe(r) + " leaves the " + std::to_string(img.width) + "x" +
                                          std::to_string(img.height) + " image");
}

void check_mask(const ImageView& img, const PixelMask* m) {
  if (m && !m->bad.empty() && (m->width != img.width || m->height != img.height))
    throw Error(ErrorClass::bad_data, "defect mask size differs from the image size");
}

double median_of(std::vector<double>& v) {
  const std::size_t n = v.size();
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(n / 2), v.end());
  double hi = v[n / 2];
  if (n % 2) return hi;
  double lo = *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(n / 2));
  return (lo + hi) / 2;
}

PatchValue robust_of(std::vector<double>& px, std::size_t total, double k, const Rect& r) {
  if (px.empty()) throw Error(ErrorClass::bad_data, describe(r) + " has no usable (non-defective) pixel");
  PatchValue pv;
  pv.total = total;
  pv.good = px.size();
  pv.median = median_of(px);
  double sum = 0;
  for (double v : px)
    if (std::abs(v - pv.median) <= k) {
      sum += v;
      ++pv.used;
    }
  // The median itself is always within the band, so used > 0 except for an even count split wider than 2k.
  pv.value = pv.used ? sum / static_cast<double>(pv.used) : pv.median;
  return pv;
}
}  // namespace

std::size_t PixelMask::count() const {
  return static_cast<std::size_t>(std::count_if(bad.begin(), bad.end(), [](std::uint8_t b) { return b != 0; }));
}

double RobustOptions::effective_k() const {
  if (k) {
    if (!(*k >= 0)) throw Error(ErrorClass::bad_parameter, "robust band half-width k must be >= 0");
    return *k;
  }
  if (bit_depth < 1 || bit_depth > 32) throw Error(ErrorClass::bad_parameter, "bit depth must be 1..32");
  return 5.0 * std::ldexp(1.0, bit_depth - 8);
}

PatchValue robust_patch_value(const ImageView& img, const Rect& r, const RobustOptions& opt, const PixelMask* defects) {
  check_region(img, r);
  check_mask(img, defects);
  const double k = opt.effective_k();
  thread_local std::vector<double> px;  // reused: 140 patches must not mean 140 allocations
  px.clear();
  px.reserve(r.width * r.height);
  for (std::size_t y = r.y; y < r.y + r.height; ++y)
    for (std::size_t x = r.x; x < r.x + r.width; ++x) {
      if (defects && defects->is_bad(x, y)) continue;
      float v = img.at(x, y);
      if (!std::isfinite(v))
        throw Error(ErrorClass::bad_data, "pixel (" + std::to_string(x) + "," + std::to_string(y) + ") is not finite");
      px.push_back(v);
    }
  return robust_of(px, r.width * r.height, k, r);
}

std::array<PatchValue, 3> cfa_patch_values(const ImageView& raw, const Rect& r, CfaPattern pattern,
                                           const RobustOptions& opt, const PixelMask* defects) {
  check_region(raw, r);
  check_mask(raw, defects);
  // Colour index (0 R, 1 G, 2 B) of the 2×2 cell position (x&1, y&1).
  int cell[2][2];  // [y&1][x&1]
  switch (pattern) {
    case CfaPattern::rggb: cell[0][0] = 0, cell[0][1] = 1, cell[1][0] = 1, cell[1][1] = 2; break;
    case CfaPattern::bggr: cell[0][0] = 2, cell[0][1] = 1, cell[1][0] = 1, cell[1][1] = 0; break;
    case CfaPattern::grbg: cell[0][0] = 1, cell[0][1] = 0, cell[1][0] = 2, cell[1][1] = 1; break;
    case CfaPattern::gbrg: cell[0][0] = 1, cell[0][1] = 2, cell[1][0] = 0, cell[1][1] = 1; break;
  }
  std::array<std::vector<double>, 3> px;
  std::array<std::size_t, 3> total{};
  for (std::size_t y = r.y; y < r.y + r.height; ++y)
    for (std::size_t x = r.x; x < r.x + r.width; ++x) {
      int c = cell[y & 1][x & 1];
      ++total[c];
      if (defects && defects->is_bad(x, y)) continue;
      px[c].push_back(raw.at(x, y));
    }
  const double k = opt.effective_k();
  return {robust_of(px[0], total[0], k, r), robust_of(px[1], total[1], k, r), robust_of(px[2], total[2], k, r)};
}

PixelMask defect_map(const ImageView& dark, const ImageView& flat, const DefectOptions& opt) {
  const ImageView& ref = dark.data ? dark : flat;
  if (!ref.data) throw Error(ErrorClass::bad_parameter, "defect map needs a dark frame, a flat frame or both");
  if (dark.data && flat.data && (dark.width != flat.width || dark.height != flat.height))
    throw Error(ErrorClass::bad_data, "dark and flat frames differ in size");
  PixelMask m{ref.width, ref.height, std::vector<std::uint8_t>(ref.width * ref.height, 0)};
  auto pixels = [](const ImageView& im) {
    std::vector<double> v;
    v.reserve(im.width * im.height);
    for (std::size_t y = 0; y < im.height; ++y)
      for (std::size_t x = 0; x < im.width; ++x) v.push_back(im.at(x, y));
    return v;
  };
  if (dark.data) {
    auto v = pixels(dark);
    double med = median_of(v);
    for (auto& d : v) d = std::abs(d - med);
    double sigma = 1.4826 * median_of(v);  // MAD: hot pixels must not inflate their own threshold
    if (sigma <= 0) sigma = 1.0;
    for (std::size_t y = 0; y < dark.height; ++y)
      for (std::size_t x = 0; x < dark.width; ++x)
        if (dark.at(x, y) > med + opt.hot_sigma * sigma) m.bad[y * m.width + x] = 1;
  }
  if (flat.data) {
    auto v = pixels(flat);
    double med = median_of(v);
    if (!(med > 0)) throw Error(ErrorClass::bad_data, "flat field has a non-positive median; is it a flat?");
    for (std::size_t y = 0; y < flat.height; ++y)
      for (std::size_t x = 0; x < flat.width; ++x) {
        double f = flat.at(x, y);
        if (f < opt.dead_fraction * med || f > opt.bright_fraction * med) m.bad[y * m.width + x] = 1;
      }
  }
  return m;
}

std::vector<NoiseRow> noise_vs_averaging(std::span<const ImageView> frames, std::span<const Rect> regions,
                                         std::span<const std::size_t> subsets, const PixelMask* defects) {
  if (frames.empty()) throw Error(ErrorClass::bad_data, "no frames given");
  if (regions.empty()) throw Error(ErrorClass::bad_data, "no patch regions given");
  const ImageView& f0 = frames.front();
  for (std::size_t i = 0; i < frames.size(); ++i)
    if (frames[i].width != f0.width || frames[i].height != f0.height || !frames[i].data)
      throw Error(ErrorClass::bad_data, "frame " + std::to_string(i + 1) + " differs in size from frame 1");
  for (const auto& r : regions) check_region(f0, r);
  check_mask(f0, defects);
  std::vector<NoiseRow> out;
  std::vector<float> avg(f0.width * f0.height);
  for (std::size_t n : subsets) {
    if (n == 0 || n > frames.size())
      throw Error(ErrorClass::bad_parameter, "subset of " + std::to_string(n) + " frames requested, " +
                                                 std::to_string(frames.size()) + " available");
    // Only the patch regions are averaged: that is all the statistic needs.
    NoiseRow row;
    row.frames = n;
    for (const auto& r : regions) {
      std::vector<double> px;
      for (std::size_t y = r.y; y < r.y + r.height; ++y)
        for (std::size_t x = r.x; x < r.x + r.width; ++x) {
          if (defects && defects->is_bad(x, y)) continue;
          double s = 0;
          for (std::size_t i = 0; i < n; ++i) s += frames[i].at(x, y);
          px.push_back(s / static_cast<double>(n));
        }
      if (px.empty()) throw Error(ErrorClass::bad_data, describe(r) + " has no usable pixel");
      row.patch_stdev.push_back(summarize(px).stdev);
    }
    row.summary = summarize(row.patch_stdev);
    out.push_back(std::move(row));
  }
  return out;
}

}  // namespace colorlab::analysis
