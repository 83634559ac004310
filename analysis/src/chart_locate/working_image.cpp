#include <algorithm>
#include <cmath>
#include <string>

#include <opencv2/imgproc.hpp>

#include "colorlab/core/error.hpp"
#include "internal.hpp"

namespace colorlab::analysis::chart_detail {
namespace {
constexpr int kMaxWorkingSide = 1800;  // px: patches stay ≥ ~10 px across for a chart filling a fifth of the frame
}

void check_photo(const PhotoView& p) {
  if (!p.data || p.width < 16 || p.height < 16)
    throw Error(ErrorClass::bad_data, "photo is empty or smaller than 16×16 pixels");
  if (p.channels != 1 && p.channels != 3)
    throw Error(ErrorClass::bad_parameter, "photo must have 1 or 3 channels, not " + std::to_string(p.channels));
  if (p.cfa && p.channels != 1) throw Error(ErrorClass::bad_parameter, "a CFA mosaic has one channel");
  if (p.row_stride() < static_cast<std::size_t>(p.width) * p.channels)
    throw Error(ErrorClass::bad_parameter, "photo row stride is shorter than a row");
}

cv::Mat wrap(const PhotoView& p) {
  const int depth = p.type == SampleType::u8 ? CV_8U : CV_16U;
  const std::size_t elem = p.type == SampleType::u8 ? 1 : 2;
  return cv::Mat(p.height, p.width, CV_MAKETYPE(depth, p.channels), const_cast<void*>(p.data), p.row_stride() * elem);
}

WorkingImage make_working_image(const PhotoView& p) {
  check_photo(p);
  cv::Mat src = wrap(p), grey;
  WorkingImage w;
  if (p.cfa) {
    // 2×2 binning averages one R, two G and one B: a luminance-like image without the mosaic.
    cv::resize(src, grey, cv::Size(p.width / 2, p.height / 2), 0, 0, cv::INTER_AREA);
    w.scale = 0.5;
  } else if (p.channels == 3) {
    cv::cvtColor(src, grey, cv::COLOR_RGB2GRAY);
  } else {
    grey = src;
  }
  const int side = std::max(grey.cols, grey.rows);
  if (side > kMaxWorkingSide) {
    const double f = double(kMaxWorkingSide) / side;
    cv::Mat small;
    cv::resize(grey, small, cv::Size(), f, f, cv::INTER_AREA);
    w.scale *= double(small.cols) / grey.cols;
    grey = small;
  }
  // Stretch black level … 99.5th percentile to 0..255; a linear raw gets a square root so dark patches separate
  // from the chart's black surround.
  cv::Mat f32;
  grey.convertTo(f32, CV_32F);
  std::vector<float> sample;
  sample.reserve(static_cast<std::size_t>(f32.total() / 16 + 1));
  for (int y = 0; y < f32.rows; y += 4)
    for (int x = 0; x < f32.cols; x += 4) sample.push_back(f32.at<float>(y, x));
  const std::size_t k = sample.size() * 995 / 1000;
  std::nth_element(sample.begin(), sample.begin() + static_cast<std::ptrdiff_t>(k), sample.end());
  const double black = p.black_level, white = std::max<double>(sample[k], black + 1);
  const bool root = p.cfa.has_value();
  w.grey.create(f32.size(), CV_8U);
  for (int y = 0; y < f32.rows; ++y) {
    const float* s = f32.ptr<float>(y);
    std::uint8_t* d = w.grey.ptr<std::uint8_t>(y);
    for (int x = 0; x < f32.cols; ++x) {
      double v = std::clamp((s[x] - black) / (white - black), 0.0, 1.0);
      if (root) v = std::sqrt(v);
      d[x] = static_cast<std::uint8_t>(std::lround(255.0 * v));
    }
  }
  return w;
}

}  // namespace colorlab::analysis::chart_detail
