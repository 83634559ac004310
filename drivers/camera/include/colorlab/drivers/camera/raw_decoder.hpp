#pragma once
// LibRaw front end: a raw file (DNG, CR2, ...) on disk or in memory -> undemosaiced counts with
// black and white levels, CFA pattern and the visible area inside the masked margins, i.e. what
// `dcraw -D -4` writes. LibRaw objects are not shareable between threads, so use one decoder per
// thread (for_this_thread()).
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "colorlab/drivers/camera/raw_image.hpp"

namespace colorlab::drivers::camera {

struct RawFileInfo {
  std::string make;
  std::string model;
  float iso = 0;
  float shutter_s = 0;
  float aperture_f = 0;
  std::int64_t timestamp = 0;  // EXIF capture time, seconds since the epoch (0 if absent)
};

class RawDecoder {
 public:
  RawDecoder();
  ~RawDecoder();
  RawDecoder(const RawDecoder&) = delete;
  RawDecoder& operator=(const RawDecoder&) = delete;

  // The returned view stays valid until the next decode on this object. Errors: not_found,
  // io_error, bad_data (not a raw file / corrupt), unsupported (no single-plane CFA raw).
  RawImage decode_file(const std::filesystem::path& file);
  // `bytes` must stay alive only for the duration of the call.
  RawImage decode_buffer(std::span<const std::uint8_t> bytes, std::string_view what = "buffer");

  const RawFileInfo& info() const;

  static RawDecoder& for_this_thread();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace colorlab::drivers::camera
