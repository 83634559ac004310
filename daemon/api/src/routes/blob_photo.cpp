#include "blob_photo.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>

#include "colorlab/campaigns/frame_keeper.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/drivers/camera/raw_decoder.hpp"

namespace colorlab::daemon {

namespace fs = std::filesystem;
namespace ca = analysis;
using nlohmann::json;

namespace {

std::optional<ca::CfaPattern> cfa_from_name(const std::string& name) {
  if (name == "RGGB") return ca::CfaPattern::rggb;
  if (name == "BGGR") return ca::CfaPattern::bggr;
  if (name == "GRBG") return ca::CfaPattern::grbg;
  if (name == "GBRG") return ca::CfaPattern::gbrg;
  return std::nullopt;  // "mono" and anything else: one grey channel
}

int bits_for(double white_level) {
  int bits = 1;
  while (bits < 16 && std::ldexp(1.0, bits) <= white_level) ++bits;
  return bits;
}

BlobPhoto from_raw_file(const fs::path& file) {
  auto& decoder = drivers::camera::RawDecoder::for_this_thread();
  const auto image = decoder.decode_file(file);
  BlobPhoto out;
  out.photo.width = static_cast<int>(image.width);
  out.photo.height = static_cast<int>(image.height);
  out.photo.channels = 1;
  out.photo.type = ca::SampleType::u16;
  out.photo.bytes.resize(image.width * image.height * sizeof(std::uint16_t));
  auto* dst = reinterpret_cast<std::uint16_t*>(out.photo.bytes.data());
  for (std::size_t y = 0; y < image.height; ++y) {
    const auto row = image.row(y);
    std::copy(row.begin(), row.end(), dst + y * image.width);
  }
  out.cfa = cfa_from_name(image.cfa.name());
  out.black_level = image.black_level[0];
  out.bits = image.white_level > 0 ? bits_for(image.white_level) : static_cast<int>(image.bits_per_sample);
  return out;
}

// An array's samples as 16-bit: integers as they are; floats (an average of N frames) scaled by the largest power
// of two that keeps the brightest sample in range, so the locator's robust band still means "counts".
BlobPhoto from_array(const fs::path& file, const json& meta) {
  const std::string dtype = meta.value("dtype", std::string());
  const json shape = meta.value("shape", json::array());
  if (!shape.is_array() || shape.size() < 2 || shape.size() > 3 || !shape[0].is_number_integer() || !shape[1].is_number_integer() ||
      (shape.size() == 3 && !shape[2].is_number_integer()))
    throw Error(ErrorClass::bad_data, "the array's meta has no shape [h, w] or [h, w, c]");
  const long h = shape[0].get<long>(), w = shape[1].get<long>(), c = shape.size() == 3 ? shape[2].get<long>() : 1;
  if (h <= 0 || w <= 0 || (c != 1 && c != 3)) throw Error(ErrorClass::unsupported, "an array of shape " + shape.dump() + " is not a photograph");
  const std::size_t item = dtype == "<f4" ? 4 : dtype == "<f8"                   ? 8
                                            : dtype == "<u2"                     ? 2
                                            : (dtype == "|u1" || dtype == "<u1") ? 1
                                                                                 : 0;
  if (item == 0) throw Error(ErrorClass::unsupported, "the chart is located in arrays of dtype <f4, <f8, <u2 or u1, not '" + dtype + "'");
  const std::size_t n = static_cast<std::size_t>(h) * static_cast<std::size_t>(w) * static_cast<std::size_t>(c);
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(ErrorClass::io_error, "cannot open " + file.string());
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
  if (bytes.size() != n * item)
    throw Error(ErrorClass::bad_data, "the array holds " + std::to_string(bytes.size()) + " bytes, its shape and dtype say " + std::to_string(n * item));
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) {
    const char* s = bytes.data() + i * item;
    if (item == 4) {
      float f;
      std::memcpy(&f, s, 4);
      v[i] = f;
    } else if (item == 8) {
      std::memcpy(&v[i], s, 8);
    } else if (item == 2) {
      std::uint16_t u;
      std::memcpy(&u, s, 2);
      v[i] = u;
    } else {
      v[i] = static_cast<unsigned char>(*s);
    }
  }
  BlobPhoto out;
  out.photo.width = static_cast<int>(w);
  out.photo.height = static_cast<int>(h);
  out.photo.channels = static_cast<int>(c);
  out.photo.type = item == 1 ? ca::SampleType::u8 : ca::SampleType::u16;
  if (c == 1) out.cfa = cfa_from_name(meta.value("cfa", std::string()));
  if (out.cfa && meta.contains("black_level") && meta["black_level"].is_number()) out.black_level = meta["black_level"].get<double>();
  double top = 0;
  for (double x : v)
    if (std::isfinite(x)) top = std::max(top, x);
  const double white = meta.contains("white_level") && meta["white_level"].is_number() ? meta["white_level"].get<double>() : top;
  out.bits = item == 1 ? 8 : bits_for(std::max(1.0, white));
  if (item == 4 || item == 8) out.scale = std::ldexp(1.0, std::max(0, 16 - bits_for(std::max({1.0, top, white}))));
  out.photo.bytes.resize(n * (item == 1 ? 1 : 2));
  for (std::size_t i = 0; i < n; ++i) {
    const double x = std::isfinite(v[i]) ? std::clamp(std::round(v[i] * out.scale), 0.0, item == 1 ? 255.0 : 65535.0) : 0.0;
    if (item == 1) out.photo.bytes[i] = static_cast<std::uint8_t>(x);
    else reinterpret_cast<std::uint16_t*>(out.photo.bytes.data())[i] = static_cast<std::uint16_t>(x);
  }
  return out;
}

}  // namespace

ca::PhotoView BlobPhoto::view() const {
  ca::PhotoView v = photo.view();
  v.cfa = cfa;
  v.black_level = black_level * scale;
  // Scaled samples have scaled noise: the robust band follows the bits they now span.
  v.bit_depth = bits > 0 ? std::min(16, bits + static_cast<int>(std::lround(std::log2(scale)))) : 0;
  return v;
}

BlobPhoto read_blob_photo(const fs::path& file, const std::string& media_type, const json& meta) {
  if (media_type == campaigns::kArrayMediaType) return from_array(file, meta);
  if (media_type == "image/x-adobe-dng" || media_type == "image/x-canon-cr2" || media_type == "image/x-nikon-nef") return from_raw_file(file);
  if (media_type == "image/tiff" || media_type == "image/jpeg" || media_type == "image/png") {
    BlobPhoto out;
    out.photo = ca::read_photo(file);
    return out;
  }
  throw Error(ErrorClass::unsupported, "a blob of type " + media_type + " is not a photograph to locate a chart in",
              "give a raw file, a colorlab array, a TIFF, JPEG or PNG (GET /v1/runs/{id}/blobs lists a run's)");
}

}  // namespace colorlab::daemon
