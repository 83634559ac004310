#include "colorlab/drivers/camera/raw_image.hpp"

#include <algorithm>

namespace colorlab::drivers::camera {

CfaPattern CfaPattern::rggb() {
  CfaPattern p;
  p.cell = {{{CfaColor::red, CfaColor::green}, {CfaColor::green, CfaColor::blue}}};
  return p;
}

CfaPattern CfaPattern::monochrome() {
  CfaPattern p;
  p.cell = {{{CfaColor::none, CfaColor::none}, {CfaColor::none, CfaColor::none}}};
  return p;
}

std::string CfaPattern::name() const {
  if (!is_mosaic()) return "mono";
  std::string s;
  for (const auto& r : cell) {
    for (CfaColor c : r) s += "RGB?"[static_cast<int>(c)];
  }
  return s;
}

OwnedRawImage OwnedRawImage::copy_of(const RawImage& image) {
  OwnedRawImage out;
  out.meta = image;
  out.meta.row_stride = image.raw_width;
  out.storage.resize(image.raw_width * image.raw_height);
  for (std::size_t y = 0; y < image.raw_height; ++y) {
    const std::uint16_t* src = image.pixels + y * image.row_stride;
    std::copy(src, src + image.raw_width, out.storage.begin() + static_cast<std::ptrdiff_t>(y * image.raw_width));
  }
  out.meta.pixels = nullptr;
  return out;
}

}  // namespace colorlab::drivers::camera
