#include <algorithm>
#include <cmath>
#include <string>

#include "colorlab/core/error.hpp"
#include "internal.hpp"

namespace colorlab::analysis {
namespace {

using chart_detail::grid_to_image;

// Half-side of the largest axis-aligned square centred on `c` inside the convex quad `q`.
double inscribed_half_side(const std::array<cv::Point2d, 4>& q, cv::Point2d c) {
  double h = 1e300;
  for (int i = 0; i < 4; ++i) {
    const cv::Point2d a = q[static_cast<std::size_t>(i)], b = q[static_cast<std::size_t>((i + 1) % 4)];
    const cv::Point2d e = b - a;
    const double len = std::hypot(e.x, e.y);
    if (len <= 0) return 0;
    const cv::Point2d n(-e.y / len, e.x / len);
    const double d = std::abs(n.dot(c - a));
    h = std::min(h, d / (std::abs(n.x) + std::abs(n.y)));
  }
  return h;
}

template <typename T>
void copy_channel(const PhotoView& p, const Rect& r, int channel, std::vector<float>& out) {
  const T* base = static_cast<const T*>(p.data);
  out.resize(r.width * r.height);
  const std::size_t stride = p.row_stride(), ch = static_cast<std::size_t>(p.channels);
  for (std::size_t y = 0; y < r.height; ++y) {
    const T* row = base + (r.y + y) * stride + r.x * ch + static_cast<std::size_t>(channel);
    float* dst = out.data() + y * r.width;
    for (std::size_t x = 0; x < r.width; ++x) dst[x] = static_cast<float>(row[x * ch]);
  }
}

void copy_channel(const PhotoView& p, const Rect& r, int channel, std::vector<float>& out) {
  if (p.type == SampleType::u8) copy_channel<std::uint8_t>(p, r, channel, out);
  else copy_channel<std::uint16_t>(p, r, channel, out);
}

PixelMask sub_mask(const PixelMask& m, const Rect& r) {
  PixelMask s{r.width, r.height, std::vector<std::uint8_t>(r.width * r.height, 0)};
  if (m.bad.empty()) return s;
  for (std::size_t y = 0; y < r.height; ++y)
    for (std::size_t x = 0; x < r.width; ++x) s.bad[y * r.width + x] = m.bad[(r.y + y) * m.width + r.x + x];
  return s;
}

}  // namespace

std::vector<ChartPatchSample> sample_chart(const PhotoView& photo, const ChartLayout& L, const std::array<double, 9>& homography,
                                           const LocateOptions& o) {
  chart_detail::check_photo(photo);
  if (!(o.sample_fraction > 0.05 && o.sample_fraction <= 1.0))
    throw Error(ErrorClass::bad_parameter, "sample fraction must be within (0.05, 1], got " + std::to_string(o.sample_fraction));
  if (o.defects && !o.defects->bad.empty() &&
      (o.defects->width != static_cast<std::size_t>(photo.width) || o.defects->height != static_cast<std::size_t>(photo.height)))
    throw Error(ErrorClass::bad_parameter, "defect map size differs from the photo size");
  const cv::Matx33d h = chart_detail::from_array(homography);
  RobustOptions ro;
  ro.bit_depth = photo.bits();
  ro.k = o.robust_k;
  const double half = L.patch_size * o.sample_fraction / 2;
  std::vector<ChartPatchSample> out;
  out.reserve(static_cast<std::size_t>(L.size()));
  thread_local std::vector<float> buf;
  for (int k = 0; k < L.size(); ++k) {
    ChartPatchSample s;
    s.id = L.ids[static_cast<std::size_t>(k)];
    const double gx = L.centre_x(k), gy = L.centre_y(k);
    const cv::Point2d c = grid_to_image(h, {gx, gy}, o.lens);
    const std::array<cv::Point2d, 4> q{grid_to_image(h, {gx - half, gy - half}, o.lens), grid_to_image(h, {gx + half, gy - half}, o.lens),
                                       grid_to_image(h, {gx + half, gy + half}, o.lens), grid_to_image(h, {gx - half, gy + half}, o.lens)};
    s.centre = {c.x, c.y};
    const double hs = inscribed_half_side(q, c);
    long x0 = static_cast<long>(std::ceil(c.x - hs)), x1 = static_cast<long>(std::floor(c.x + hs));
    long y0 = static_cast<long>(std::ceil(c.y - hs)), y1 = static_cast<long>(std::floor(c.y + hs));
    if (photo.cfa) {  // whole 2×2 cells, so the copied block starts on the mosaic's own phase
      x0 += x0 & 1, y0 += y0 & 1;
      if ((x1 - x0 + 1) % 2) --x1;
      if ((y1 - y0 + 1) % 2) --y1;
    }
    if (x1 < x0 || y1 < y0)
      throw Error(ErrorClass::needs_operator, "patch " + s.id + " is too small in this photo to sample",
                  "move the camera closer or use a larger sample fraction");
    if (x0 < 0 || y0 < 0 || x1 >= photo.width || y1 >= photo.height)
      throw Error(ErrorClass::needs_operator, "patch " + s.id + " lies outside the photo",
                  "the whole chart must be in the frame; check the corners given");
    s.region = {static_cast<std::size_t>(x0), static_cast<std::size_t>(y0), static_cast<std::size_t>(x1 - x0 + 1),
                static_cast<std::size_t>(y1 - y0 + 1)};
    const Rect local{0, 0, s.region.width, s.region.height};
    PixelMask mask;
    if (o.defects && !o.defects->bad.empty()) mask = sub_mask(*o.defects, s.region);
    const PixelMask* m = mask.bad.empty() ? nullptr : &mask;
    if (photo.cfa) {
      copy_channel(photo, s.region, 0, buf);
      const ImageView v{buf.data(), s.region.width, s.region.height, s.region.width};
      s.value = cfa_patch_values(v, local, *photo.cfa, ro, m);
      s.channels = 3;
    } else {
      for (int ch = 0; ch < photo.channels; ++ch) {
        copy_channel(photo, s.region, ch, buf);
        const ImageView v{buf.data(), s.region.width, s.region.height, s.region.width};
        s.value[static_cast<std::size_t>(ch)] = robust_patch_value(v, local, ro, m);
      }
      s.channels = photo.channels;
    }
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace colorlab::analysis
