#include "blob_preview.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "colorlab/campaigns/frame_keeper.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/drivers/camera/raw_decoder.hpp"

namespace colorlab::daemon {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr int kMaxSide = 1024;

// Samples as floats, one or three channels, and where the CFA cell colours are (if a mosaic).
struct Plane {
  int height = 0, width = 0, channels = 1;
  std::vector<float> values;  // row-major, interleaved channels
  std::string cfa;            // "RGGB", …; empty or "mono" when not a mosaic
  double black = 0;
};

std::vector<char> read_file(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(ErrorClass::io_error, "cannot open " + file.string());
  return std::vector<char>(std::istreambuf_iterator<char>(in), {});
}

Plane read_array(const fs::path& file, const json& meta) {
  const std::string dtype = meta.value("dtype", std::string());
  if (!meta.contains("shape") || !meta["shape"].is_array() || meta["shape"].size() < 2 || meta["shape"].size() > 3) {
    throw Error(ErrorClass::bad_data, "the array's meta has no shape [h, w] or [h, w, c]");
  }
  Plane p;
  p.height = meta["shape"][0].get<int>();
  p.width = meta["shape"][1].get<int>();
  p.channels = meta["shape"].size() == 3 ? meta["shape"][2].get<int>() : 1;
  if (p.height <= 0 || p.width <= 0 || (p.channels != 1 && p.channels != 3)) throw Error(ErrorClass::bad_data, "the array's shape is not an image");
  std::size_t item = dtype == "<f4" ? 4 : dtype == "<f8"                   ? 8
                                      : dtype == "<u2"                     ? 2
                                      : (dtype == "|u1" || dtype == "<u1") ? 1
                                                                           : 0;
  if (item == 0) throw Error(ErrorClass::unsupported, "no preview for arrays of dtype '" + dtype + "'", "previews show <f4, <f8, <u2 and u1 arrays");
  const std::size_t n = static_cast<std::size_t>(p.height) * p.width * p.channels;
  auto bytes = read_file(file);
  if (bytes.size() != n * item) {
    throw Error(ErrorClass::bad_data, "the array holds " + std::to_string(bytes.size()) + " bytes, its shape and dtype say " +
                                          std::to_string(n * item));
  }
  p.values.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const char* s = bytes.data() + i * item;
    if (item == 4) {
      float v;
      std::memcpy(&v, s, 4);
      p.values[i] = v;
    } else if (item == 8) {
      double v;
      std::memcpy(&v, s, 8);
      p.values[i] = static_cast<float>(v);
    } else if (item == 2) {
      std::uint16_t v;
      std::memcpy(&v, s, 2);
      p.values[i] = v;
    } else {
      p.values[i] = static_cast<unsigned char>(*s);
    }
  }
  p.cfa = meta.value("cfa", std::string());
  if (meta.contains("black_level") && meta["black_level"].is_number()) p.black = meta["black_level"].get<double>();
  return p;
}

Plane read_raw(const fs::path& file) {
  auto& decoder = drivers::camera::RawDecoder::for_this_thread();
  auto image = decoder.decode_file(file);
  Plane p;
  p.height = static_cast<int>(image.height);
  p.width = static_cast<int>(image.width);
  p.values.resize(image.width * image.height);
  for (std::size_t y = 0; y < image.height; ++y) {
    auto row = image.row(y);
    for (std::size_t x = 0; x < image.width; ++x) p.values[y * image.width + x] = row[x];
  }
  p.cfa = image.cfa.name();
  p.black = image.black_level[0];
  return p;
}

// A mosaic's 2×2 cells as one RGB pixel each (greens averaged): half size, no demosaicing guesses.
Plane half_size_rgb(const Plane& m) {
  Plane out;
  out.height = m.height / 2;
  out.width = m.width / 2;
  out.channels = 3;
  out.values.assign(static_cast<std::size_t>(out.height) * out.width * 3, 0.f);
  int index[4];  // channel of each cell position [row%2*2 + col%2]
  for (int i = 0; i < 4; ++i) index[i] = m.cfa[static_cast<std::size_t>(i)] == 'R' ? 0 : m.cfa[static_cast<std::size_t>(i)] == 'B' ? 2
                                                                                                                                   : 1;
  for (int y = 0; y < out.height; ++y) {
    for (int x = 0; x < out.width; ++x) {
      float sum[3] = {0, 0, 0};
      int count[3] = {0, 0, 0};
      for (int c = 0; c < 4; ++c) {
        int yy = 2 * y + c / 2, xx = 2 * x + c % 2;
        sum[index[c]] += m.values[static_cast<std::size_t>(yy) * m.width + xx] - static_cast<float>(m.black);
        ++count[index[c]];
      }
      for (int k = 0; k < 3; ++k) out.values[(static_cast<std::size_t>(y) * out.width + x) * 3 + k] = count[k] ? sum[k] / count[k] : 0.f;
    }
  }
  return out;
}

double encode_srgb(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055; }

// Scaled so the 99.5th percentile is white (a chart's white patch, not a specular glint), sRGB gamma.
cv::Mat to_8bit(const Plane& p) {
  std::vector<float> sample;
  const std::size_t step = std::max<std::size_t>(1, p.values.size() / 200000);
  for (std::size_t i = 0; i < p.values.size(); i += step) {
    if (std::isfinite(p.values[i])) sample.push_back(p.values[i] - (p.cfa.size() == 4 ? 0.f : static_cast<float>(p.black)));
  }
  double white = 1;
  if (!sample.empty()) {
    auto nth = sample.begin() + static_cast<std::ptrdiff_t>(0.995 * static_cast<double>(sample.size() - 1));
    std::nth_element(sample.begin(), nth, sample.end());
    if (*nth > 0) white = *nth;
  }
  const double black = p.cfa.size() == 4 ? 0 : p.black;  // a half-size mosaic has its black taken off
  cv::Mat out(p.height, p.width, p.channels == 3 ? CV_8UC3 : CV_8UC1);
  unsigned char lut[4097];
  for (int i = 0; i <= 4096; ++i) lut[i] = static_cast<unsigned char>(std::lround(255 * encode_srgb(i / 4096.0)));
  for (int y = 0; y < p.height; ++y) {
    auto* row = out.ptr<unsigned char>(y);
    for (int x = 0; x < p.width; ++x) {
      for (int c = 0; c < p.channels; ++c) {
        const double v = (p.values[(static_cast<std::size_t>(y) * p.width + x) * p.channels + c] - black) / white;
        const int k = std::isfinite(v) ? static_cast<int>(std::lround(std::clamp(v, 0.0, 1.0) * 4096)) : 0;
        // OpenCV writes BGR.
        row[x * p.channels + (p.channels == 3 ? 2 - c : 0)] = lut[k];
      }
    }
  }
  return out;
}

bool is_mosaic(const std::string& cfa) {
  if (cfa.size() != 4) return false;
  return std::all_of(cfa.begin(), cfa.end(), [](char c) { return c == 'R' || c == 'G' || c == 'B'; });
}

cv::Mat preview_of_plane(Plane p) {
  if (p.channels == 1 && is_mosaic(p.cfa) && p.width >= 2 && p.height >= 2) return to_8bit(half_size_rgb(p));
  p.cfa.clear();
  return to_8bit(p);
}

}  // namespace

std::vector<std::uint8_t> render_preview_png(const fs::path& file, const std::string& media_type, const json& meta) {
  cv::Mat image;
  if (media_type == campaigns::kArrayMediaType) {
    image = preview_of_plane(read_array(file, meta));
  } else if (media_type == "image/x-adobe-dng" || media_type == "image/x-canon-cr2" || media_type == "image/x-nikon-nef") {
    image = preview_of_plane(read_raw(file));
  } else if (media_type == "image/tiff" || media_type == "image/jpeg" || media_type == "image/png") {
    image = cv::imread(file.string(), cv::IMREAD_COLOR | cv::IMREAD_ANYDEPTH);
    if (image.empty()) throw Error(ErrorClass::bad_data, "cannot decode " + file.filename().string() + " as " + media_type);
    if (image.depth() == CV_16U) image.convertTo(image, CV_8U, 1.0 / 257);
    else if (image.depth() != CV_8U) image.convertTo(image, CV_8U);
  } else {
    throw Error(ErrorClass::unsupported, "no preview for " + media_type,
                "previews show raw files, colorlab arrays, TIFF, JPEG and PNG");
  }
  const int side = std::max(image.cols, image.rows);
  if (side > kMaxSide) {
    const double f = static_cast<double>(kMaxSide) / side;
    cv::Mat small;
    cv::resize(image, small, cv::Size(std::max(1, static_cast<int>(image.cols * f)), std::max(1, static_cast<int>(image.rows * f))), 0, 0,
               cv::INTER_AREA);
    image = small;
  }
  std::vector<std::uint8_t> png;
  if (!cv::imencode(".png", image, png)) throw Error(ErrorClass::internal, "OpenCV could not encode the preview as PNG");
  return png;
}

}  // namespace colorlab::daemon
