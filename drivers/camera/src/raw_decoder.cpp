#include "colorlab/drivers/camera/raw_decoder.hpp"

#include <libraw/libraw.h>

#include <cmath>
#include <system_error>

#include "colorlab/core/error.hpp"

namespace colorlab::drivers::camera {

struct RawDecoder::Impl {
  LibRaw lr;
  RawFileInfo info;
};

RawDecoder::RawDecoder() : impl_(std::make_unique<Impl>()) {}
RawDecoder::~RawDecoder() = default;

const RawFileInfo& RawDecoder::info() const { return impl_->info; }

RawDecoder& RawDecoder::for_this_thread() {
  thread_local RawDecoder decoder;
  return decoder;
}

namespace {

[[noreturn]] void fail(int code, std::string_view step, std::string_view what) {
  ErrorInfo info;
  info.device_code = "libraw:" + std::to_string(code);
  info.message = "LibRaw " + std::string(step) + " failed on " + std::string(what) + ": " + libraw_strerror(code);
  switch (code) {
    case LIBRAW_IO_ERROR:
      info.cls = ErrorClass::io_error;
      info.hint = "check that the file is readable and complete (a download may have been cut short)";
      info.retryable = true;
      break;
    case LIBRAW_UNSUFFICIENT_MEMORY:
      info.cls = ErrorClass::internal;
      info.hint = "the machine is out of memory";
      break;
    case LIBRAW_FILE_UNSUPPORTED:
      info.cls = ErrorClass::bad_data;
      info.hint = "not a raw file LibRaw knows; set the camera's image format to RAW (CR2/DNG)";
      break;
    default:
      info.cls = ErrorClass::bad_data;
      info.hint = "the raw file is corrupt or truncated; capture it again";
  }
  throw Error(std::move(info));
}

CfaColor to_cfa(int libraw_color) {
  switch (libraw_color) {
    case 0: return CfaColor::red;
    case 1:
    case 3: return CfaColor::green;  // LibRaw numbers the second green 3
    case 2: return CfaColor::blue;
    default: return CfaColor::none;
  }
}

RawImage describe(LibRaw& lr, std::string_view what) {
  const auto& d = lr.imgdata;
  if (d.rawdata.raw_image == nullptr) {
    throw Error(ErrorClass::unsupported,
                std::string(what) + " holds no single-plane CFA raw (linear or multi-plane image)",
                "use a camera raw (CR2) or a CFA DNG; demosaiced DNG/TIFF cannot give sensor counts");
  }
  const bool mono = d.idata.filters == 0 && d.idata.colors == 1;
  if (!mono && d.idata.filters < 1000) {  // 1 = Leaf, 2 = Foveon-like, 9 = X-Trans: not a 2x2 CFA
    throw Error(ErrorClass::unsupported,
                std::string(what) + " uses a CFA layout other than 2x2 Bayer (filters=" +
                    std::to_string(d.idata.filters) + ")",
                "colorlab analyses 2x2 Bayer (RGGB, ...) or monochrome sensors only");
  }
  RawImage img;
  img.pixels = d.rawdata.raw_image;
  img.row_stride = d.sizes.raw_pitch / sizeof(std::uint16_t);
  img.raw_width = d.sizes.raw_width;
  img.raw_height = d.sizes.raw_height;
  img.left_margin = d.sizes.left_margin;
  img.top_margin = d.sizes.top_margin;
  img.width = d.sizes.width;
  img.height = d.sizes.height;
  img.cfa = CfaPattern::monochrome();
  const auto& c = d.color;
  for (int r = 0; r < 2; ++r) {
    for (int col = 0; col < 2; ++col) {
      const int colour = mono ? 0 : lr.COLOR(r, col);
      if (!mono) img.cfa.cell[r][col] = to_cfa(colour);
      // LibRaw splits black into a global level, a per-colour offset and a repeating pattern.
      unsigned black = c.black + c.cblack[colour];
      if (c.cblack[4] > 0 && c.cblack[5] > 0) {
        black += c.cblack[6 + (r % c.cblack[4]) * c.cblack[5] + (col % c.cblack[5])];
      }
      img.black_level[static_cast<std::size_t>(r * 2 + col)] = static_cast<std::uint16_t>(black);
    }
  }
  img.white_level = static_cast<std::uint16_t>(c.maximum);
  img.bits_per_sample = c.maximum > 0 ? static_cast<std::uint32_t>(std::ceil(std::log2(double(c.maximum) + 1))) : 16;
  return img;
}

}  // namespace

RawImage RawDecoder::decode_file(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) {
    throw Error(ErrorClass::not_found, "raw file " + file.string() + " does not exist",
                "check the capture directory and the file name");
  }
  LibRaw& lr = impl_->lr;
  lr.recycle();
  if (int rc = lr.open_file(file.c_str()); rc != LIBRAW_SUCCESS) fail(rc, "open", file.string());
  if (int rc = lr.unpack(); rc != LIBRAW_SUCCESS) fail(rc, "unpack", file.string());
  const auto& o = lr.imgdata.other;
  impl_->info = {lr.imgdata.idata.make, lr.imgdata.idata.model, o.iso_speed, o.shutter, o.aperture,
                 static_cast<std::int64_t>(o.timestamp)};
  return describe(lr, file.string());
}

RawImage RawDecoder::decode_buffer(std::span<const std::uint8_t> bytes, std::string_view what) {
  if (bytes.empty()) {
    throw Error(ErrorClass::bad_data, "raw buffer " + std::string(what) + " is empty",
                "the download returned no data; capture again");
  }
  LibRaw& lr = impl_->lr;
  lr.recycle();
  // LibRaw takes a non-const pointer but only reads; unpack copies the counts into its own
  // storage, so the caller's bytes are not needed afterwards.
  if (int rc = lr.open_buffer(const_cast<std::uint8_t*>(bytes.data()), bytes.size()); rc != LIBRAW_SUCCESS) {
    fail(rc, "open", what);
  }
  if (int rc = lr.unpack(); rc != LIBRAW_SUCCESS) fail(rc, "unpack", what);
  const auto& o = lr.imgdata.other;
  impl_->info = {lr.imgdata.idata.make, lr.imgdata.idata.model, o.iso_speed, o.shutter, o.aperture,
                 static_cast<std::int64_t>(o.timestamp)};
  return describe(lr, what);
}

}  // namespace colorlab::drivers::camera
