#pragma once
// A DNG with masked borders (ActiveArea), as real sensors have and as a CR2 stores them, written
// with libtiff so the decoder's margin handling is tested without a real camera file. The
// simulator's writer has no margins, which is why this small writer lives with the tests.
#include <tiffio.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <vector>

namespace colorlab::drivers::camera::test {

struct MarginDng {
  std::uint32_t raw_width = 0, raw_height = 0;
  std::uint32_t top = 0, left = 0, bottom = 0, right = 0;  // active area, DNG order
  std::vector<std::uint16_t> pixels;                       // raw_width * raw_height, RGGB from (top, left)
  float black = 256;
  std::uint32_t white = 4095;
};

inline void write_margin_dng(const std::filesystem::path& path, const MarginDng& d) {
  TIFF* tif = TIFFOpen(path.c_str(), "w");
  if (!tif) throw std::runtime_error("cannot create " + path.string());
  const std::uint16_t repeat[2] = {2, 2};
  const std::uint8_t rggb[4] = {0, 1, 1, 2};
  const std::uint8_t version[4] = {1, 4, 0, 0};
  const std::uint8_t backward[4] = {1, 1, 0, 0};
  const std::uint16_t black_repeat[2] = {1, 1};
  const std::uint32_t area[4] = {d.top, d.left, d.bottom, d.right};
  const float identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  const float neutral[3] = {0.5f, 1.0f, 0.7f};
  TIFFSetField(tif, TIFFTAG_SUBFILETYPE, 0);
  TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, d.raw_width);
  TIFFSetField(tif, TIFFTAG_IMAGELENGTH, d.raw_height);
  TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, 16);
  TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, 1);
  TIFFSetField(tif, TIFFTAG_COMPRESSION, COMPRESSION_NONE);
  TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_CFA);
  TIFFSetField(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
  TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, d.raw_height);
  TIFFSetField(tif, TIFFTAG_MAKE, "colorlab-test");
  TIFFSetField(tif, TIFFTAG_MODEL, "margins");
  TIFFSetField(tif, TIFFTAG_CFAREPEATPATTERNDIM, repeat);
  TIFFSetField(tif, TIFFTAG_CFAPATTERN, 4, rggb);
  TIFFSetField(tif, TIFFTAG_DNGVERSION, version);
  TIFFSetField(tif, TIFFTAG_DNGBACKWARDVERSION, backward);
  TIFFSetField(tif, TIFFTAG_UNIQUECAMERAMODEL, "colorlab-test margins");
  TIFFSetField(tif, TIFFTAG_BLACKLEVELREPEATDIM, black_repeat);
  TIFFSetField(tif, TIFFTAG_BLACKLEVEL, 1, &d.black);
  TIFFSetField(tif, TIFFTAG_WHITELEVEL, 1, &d.white);
  TIFFSetField(tif, TIFFTAG_ACTIVEAREA, area);
  TIFFSetField(tif, TIFFTAG_COLORMATRIX1, 9, identity);
  TIFFSetField(tif, TIFFTAG_CALIBRATIONILLUMINANT1, 21);
  TIFFSetField(tif, TIFFTAG_ASSHOTNEUTRAL, 3, neutral);
  const bool ok = TIFFWriteEncodedStrip(tif, 0, const_cast<std::uint16_t*>(d.pixels.data()),
                                        static_cast<tmsize_t>(d.pixels.size() * 2)) >= 0;
  TIFFClose(tif);
  if (!ok) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace colorlab::drivers::camera::test
