#include "colorlab/sim/camera/dng.hpp"

#include <tiffio.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <string>
#include <system_error>

#include "colorlab/core/error.hpp"

namespace colorlab::sim::camera {
namespace {

std::uint8_t cfa_code(char c) {
  switch (c) {
    case 'R': return 0;
    case 'G': return 1;
    case 'B': return 2;
    default: throw Error(ErrorClass::bad_parameter, std::string("CFA colour '") + c + "' is not R, G or B");
  }
}

void check_frame(const RawFrame& f) {
  if (f.width <= 0 || f.height <= 0 ||
      f.pixels.size() != static_cast<std::size_t>(f.width) * static_cast<std::size_t>(f.height)) {
    throw Error(ErrorClass::bad_parameter, "raw frame " + std::to_string(f.width) + "×" + std::to_string(f.height) +
                                               " does not match its " + std::to_string(f.pixels.size()) + " pixels");
  }
  if (f.cfa.size() != 4) throw Error(ErrorClass::bad_parameter, "CFA pattern \"" + f.cfa + "\" must have 4 letters");
  if (f.black_level < 0 || f.white_level <= f.black_level || f.white_level > 65535)
    throw Error(ErrorClass::bad_parameter, "raw frame black/white levels are inconsistent");
}

struct TiffCloser {
  void operator()(TIFF* t) const { TIFFClose(t); }
};

void set(TIFF* /*tif*/, bool ok, const char* what, const std::filesystem::path& path) {
  if (!ok) throw Error(ErrorClass::io_error, "writing DNG " + path.string() + ": cannot set " + what);
}

}  // namespace

void write_dng(const std::filesystem::path& path, const RawFrame& frame, const DngMetadata& meta) {
  check_frame(frame);
  static std::atomic<unsigned> counter{0};
  const std::filesystem::path tmp = path.parent_path() / ("." + path.filename().string() + ".tmp" +
                                                          std::to_string(::getpid()) + "-" + std::to_string(counter++));
  {
    // "w" without "8": classic TIFF, little-endian; a full 3504×2336 frame is 16 MB, far below 4 GB.
    std::unique_ptr<TIFF, TiffCloser> tif(TIFFOpen(tmp.c_str(), "w"));
    if (!tif) throw Error(ErrorClass::io_error, "cannot create " + tmp.string(), "check the directory exists and is writable");
    TIFF* t = tif.get();
    const auto w = static_cast<std::uint32_t>(frame.width), h = static_cast<std::uint32_t>(frame.height);
    set(t, TIFFSetField(t, TIFFTAG_SUBFILETYPE, 0), "SubfileType", path);
    set(t, TIFFSetField(t, TIFFTAG_IMAGEWIDTH, w), "ImageWidth", path);
    set(t, TIFFSetField(t, TIFFTAG_IMAGELENGTH, h), "ImageLength", path);
    set(t, TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, 16), "BitsPerSample", path);
    set(t, TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, 1), "SamplesPerPixel", path);
    set(t, TIFFSetField(t, TIFFTAG_COMPRESSION, COMPRESSION_NONE), "Compression", path);
    set(t, TIFFSetField(t, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_CFA), "Photometric", path);
    set(t, TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG), "PlanarConfig", path);
    set(t, TIFFSetField(t, TIFFTAG_ORIENTATION, ORIENTATION_TOPLEFT), "Orientation", path);
    set(t, TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, h), "RowsPerStrip", path);
    set(t, TIFFSetField(t, TIFFTAG_MAKE, meta.make.c_str()), "Make", path);
    set(t, TIFFSetField(t, TIFFTAG_MODEL, meta.model.c_str()), "Model", path);
    set(t, TIFFSetField(t, TIFFTAG_SOFTWARE, meta.software.c_str()), "Software", path);
    if (!meta.datetime.empty()) set(t, TIFFSetField(t, TIFFTAG_DATETIME, meta.datetime.c_str()), "DateTime", path);

    const std::uint16_t repeat[2] = {2, 2};
    set(t, TIFFSetField(t, TIFFTAG_CFAREPEATPATTERNDIM, repeat), "CFARepeatPatternDim", path);
    std::uint8_t pattern[4];
    for (int i = 0; i < 4; ++i) pattern[i] = cfa_code(frame.cfa[static_cast<std::size_t>(i)]);
    set(t, TIFFSetField(t, TIFFTAG_CFAPATTERN, 4, pattern), "CFAPattern", path);
    const std::uint8_t version[4] = {1, 4, 0, 0}, backward[4] = {1, 1, 0, 0};
    set(t, TIFFSetField(t, TIFFTAG_DNGVERSION, version), "DNGVersion", path);
    set(t, TIFFSetField(t, TIFFTAG_DNGBACKWARDVERSION, backward), "DNGBackwardVersion", path);
    set(t, TIFFSetField(t, TIFFTAG_UNIQUECAMERAMODEL, meta.unique_camera_model.c_str()), "UniqueCameraModel", path);
    const std::uint16_t black_repeat[2] = {1, 1};
    set(t, TIFFSetField(t, TIFFTAG_BLACKLEVELREPEATDIM, black_repeat), "BlackLevelRepeatDim", path);
    float black = static_cast<float>(frame.black_level);
    set(t, TIFFSetField(t, TIFFTAG_BLACKLEVEL, 1, &black), "BlackLevel", path);
    std::uint32_t white = static_cast<std::uint32_t>(frame.white_level);
    set(t, TIFFSetField(t, TIFFTAG_WHITELEVEL, 1, &white), "WhiteLevel", path);
    float matrix[9];
    for (int i = 0; i < 9; ++i) matrix[i] = static_cast<float>(meta.color_matrix1[static_cast<std::size_t>(i)]);
    set(t, TIFFSetField(t, TIFFTAG_COLORMATRIX1, 9, matrix), "ColorMatrix1", path);
    set(t, TIFFSetField(t, TIFFTAG_CALIBRATIONILLUMINANT1, 21), "CalibrationIlluminant1", path);  // D65
    float neutral[3];
    for (int i = 0; i < 3; ++i) neutral[i] = static_cast<float>(meta.as_shot_neutral[static_cast<std::size_t>(i)]);
    set(t, TIFFSetField(t, TIFFTAG_ASSHOTNEUTRAL, 3, neutral), "AsShotNeutral", path);

    const tmsize_t bytes = static_cast<tmsize_t>(frame.pixels.size() * sizeof(std::uint16_t));
    // libtiff does not modify the buffer for uncompressed native-endian strips.
    if (TIFFWriteEncodedStrip(t, 0, const_cast<std::uint16_t*>(frame.pixels.data()), bytes) != bytes) {
      std::filesystem::remove(tmp);
      throw Error(ErrorClass::io_error, "writing DNG " + tmp.string() + ": short write", "check free disk space");
    }
    if (!TIFFWriteDirectory(t)) {
      std::filesystem::remove(tmp);
      throw Error(ErrorClass::io_error, "writing DNG " + tmp.string() + ": cannot write the TIFF directory");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp);
    throw Error(ErrorClass::io_error, "cannot move " + tmp.string() + " to " + path.string() + ": " + ec.message());
  }
}

}  // namespace colorlab::sim::camera
