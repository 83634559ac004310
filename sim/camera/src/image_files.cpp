#include <tiffio.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <memory>
#include <string>
#include <system_error>

#include "colorlab/core/error.hpp"
#include "colorlab/sim/camera/processed.hpp"

#ifdef COLORLAB_HAVE_LIBJPEG
#include <jpeglib.h>
#endif

namespace colorlab::sim::camera {
namespace {

std::filesystem::path temp_beside(const std::filesystem::path& path) {
  static std::atomic<unsigned> counter{0};
  return path.parent_path() /
         ("." + path.filename().string() + ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
}

void publish(const std::filesystem::path& tmp, const std::filesystem::path& path) {
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp);
    throw Error(ErrorClass::io_error, "cannot move " + tmp.string() + " to " + path.string() + ": " + ec.message());
  }
}

void check_image(const RgbImage& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != std::size_t(image.width) * std::size_t(image.height) * 3)
    throw Error(ErrorClass::bad_parameter, "RGB image size does not match its samples");
}

struct TiffCloser {
  void operator()(TIFF* t) const { TIFFClose(t); }
};

}  // namespace

void write_tiff(const std::filesystem::path& path, const RgbImage& image, int bits) {
  check_image(image);
  if (bits != 8 && bits != 16) throw Error(ErrorClass::bad_parameter, "TIFF bit depth must be 8 or 16");
  const auto tmp = temp_beside(path);
  {
    std::unique_ptr<TIFF, TiffCloser> tif(TIFFOpen(tmp.c_str(), "w"));
    if (!tif) throw Error(ErrorClass::io_error, "cannot create " + tmp.string(), "check the directory exists and is writable");
    TIFF* t = tif.get();
    TIFFSetField(t, TIFFTAG_IMAGEWIDTH, static_cast<std::uint32_t>(image.width));
    TIFFSetField(t, TIFFTAG_IMAGELENGTH, static_cast<std::uint32_t>(image.height));
    TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, bits);
    TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, 3);
    TIFFSetField(t, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_RGB);
    TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
    TIFFSetField(t, TIFFTAG_COMPRESSION, COMPRESSION_NONE);
    TIFFSetField(t, TIFFTAG_ORIENTATION, ORIENTATION_TOPLEFT);
    TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, static_cast<std::uint32_t>(image.height));
    TIFFSetField(t, TIFFTAG_SOFTWARE, "colorlab-sim (Adobe RGB 1998)");
    const std::size_t n = image.rgb.size();
    bool ok;
    if (bits == 16) {
      ok = TIFFWriteEncodedStrip(t, 0, const_cast<std::uint16_t*>(image.rgb.data()), tmsize_t(n * 2)) == tmsize_t(n * 2);
    } else {
      std::vector<std::uint8_t> eight(n);
      for (std::size_t i = 0; i < n; ++i) eight[i] = static_cast<std::uint8_t>((image.rgb[i] * 255u + 32767u) / 65535u);
      ok = TIFFWriteEncodedStrip(t, 0, eight.data(), tmsize_t(n)) == tmsize_t(n);
    }
    if (!ok || !TIFFWriteDirectory(t)) {
      std::filesystem::remove(tmp);
      throw Error(ErrorClass::io_error, "writing TIFF " + tmp.string() + " failed", "check free disk space");
    }
  }
  publish(tmp, path);
}

void write_jpeg(const std::filesystem::path& path, const RgbImage& image, int quality) {
  check_image(image);
  if (quality < 1 || quality > 100) throw Error(ErrorClass::bad_parameter, "JPEG quality must be within 1..100");
#ifndef COLORLAB_HAVE_LIBJPEG
  (void)path;
  throw Error(ErrorClass::unsupported, "colorlab was built without libjpeg", "install libjpeg-dev and rebuild");
#else
  const auto tmp = temp_beside(path);
  std::FILE* file = std::fopen(tmp.c_str(), "wb");
  if (!file) throw Error(ErrorClass::io_error, "cannot create " + tmp.string(), "check the directory exists and is writable");
  jpeg_compress_struct cinfo{};
  jpeg_error_mgr jerr{};
  cinfo.err = jpeg_std_error(&jerr);
  jpeg_create_compress(&cinfo);
  jpeg_stdio_dest(&cinfo, file);
  cinfo.image_width = static_cast<JDIMENSION>(image.width);
  cinfo.image_height = static_cast<JDIMENSION>(image.height);
  cinfo.input_components = 3;
  cinfo.in_color_space = JCS_RGB;
  jpeg_set_defaults(&cinfo);
  jpeg_set_quality(&cinfo, quality, TRUE);
  for (int i = 0; i < 3; ++i) cinfo.comp_info[i].h_samp_factor = cinfo.comp_info[i].v_samp_factor = 1;  // 4:4:4
  jpeg_start_compress(&cinfo, TRUE);
  std::vector<JSAMPLE> row(std::size_t(image.width) * 3);
  while (cinfo.next_scanline < cinfo.image_height) {
    const std::uint16_t* src = &image.rgb[std::size_t(cinfo.next_scanline) * row.size()];
    for (std::size_t i = 0; i < row.size(); ++i) row[i] = static_cast<JSAMPLE>((src[i] * 255u + 32767u) / 65535u);
    JSAMPROW rows[1] = {row.data()};
    jpeg_write_scanlines(&cinfo, rows, 1);
  }
  jpeg_finish_compress(&cinfo);
  jpeg_destroy_compress(&cinfo);
  const bool failed = std::ferror(file) != 0;
  if (std::fclose(file) != 0 || failed) {
    std::filesystem::remove(tmp);
    throw Error(ErrorClass::io_error, "writing JPEG " + tmp.string() + " failed", "check free disk space");
  }
  publish(tmp, path);
#endif
}

}  // namespace colorlab::sim::camera
