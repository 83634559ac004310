#pragma once
// A renderer's image as colorlab reads it for verification (issue 23, docs/verify.md): one in-memory form
// for every input format, so the comparisons never know which file it came from. Spectral images keep their
// bands (the §7.4 comparison needs them); XYZ and RGB keep what the file says about their primaries and white.
#include <array>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace colorlab::verify {

enum class Encoding {
  spectral,  // one channel per wavelength band (Fichet, Pacanowski & Wilkie, JCGT 2021 layout in OpenEXR)
  xyz,       // CIE XYZ, 3 channels
  rgb,       // linear RGB, 3 channels, primaries and white from `chromaticities` (sRGB/Rec.709 when the file is silent)
};

// xy of red, green, blue and white, as OpenEXR's `chromaticities` attribute stores them.
using Chromaticities = std::array<std::array<double, 2>, 4>;

struct Rendering {
  int width = 0;
  int height = 0;
  Encoding encoding = Encoding::xyz;
  std::vector<double> wavelengths_nm;  // spectral: each band's centre, ascending; empty otherwise
  Chromaticities chromaticities{};     // rgb only
  bool chromaticities_from_file = false;
  // Radiometric units as the file states them (e.g. JCGT's "W.m^-2.sr^-1.nm^-1" for emissive spectral
  // channels, EXR's whiteLuminance for RGB/XYZ); empty when the file does not say, and then a verification
  // must either be given the scale or fit one factor, and say which it did.
  std::string units;
  std::optional<double> white_luminance_cd_m2;  // OpenEXR `whiteLuminance`: cd/m² of RGB (1,1,1)
  std::string source_format;                    // "openexr-spectral", "openexr-xyz", "openexr-rgb", "rgbe", "pfm"
  // Row-major from the top-left pixel, channels interleaved per pixel: channels() floats per pixel.
  std::vector<float> pixels;

  int channels() const { return encoding == Encoding::spectral ? static_cast<int>(wavelengths_nm.size()) : 3; }
  const float* pixel(int x, int y) const {
    return pixels.data() + (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) *
                               static_cast<std::size_t>(channels());
  }
};

// Reads any supported file by its content (magic bytes), not its extension. Throws colorlab::Error
// (bad_data with what is wrong and where; io_error; unsupported for a valid file of another kind).
Rendering read_rendering(const std::filesystem::path& file);

}  // namespace colorlab::verify
