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
  // spectral: JCGT's reflective `T.` layer (reflectance, no units) rather than the emissive `S0.` layer.
  bool reflective = false;
  Chromaticities chromaticities{};  // rgb only
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

// Rec. 709 / sRGB primaries with D65: OpenEXR's default when a file has no `chromaticities`.
Chromaticities rec709_chromaticities();
// Radiance's standard primaries (white E), what an RGBE file without PRIMARIES means by its format's definition.
Chromaticities radiance_chromaticities();

// Reads any supported file by its content (magic bytes), not its extension. Throws colorlab::Error
// (bad_data with what is wrong and where; io_error; unsupported for a valid file of another kind).
Rendering read_rendering(const std::filesystem::path& file);

// Each band's extent [edges[i], edges[i+1]] for a spectral rendering: JCGT's box functions meeting halfway between
// neighbouring centres, the two outer boxes as wide as their inner halves. Throws bad_data for fewer than 2 bands.
std::vector<double> band_edges_nm(const std::vector<double>& wavelengths_nm);

// JCGT 2021 channel name for a band: "S0.550,000000nm" (emissive) or "T.550,000000nm" (reflective).
std::string spectral_channel_name(double wavelength_nm, bool reflective = false);
// The band centre in nm of a JCGT spectral channel of the given layer ("S0" or "T"), nullopt if the name is not one
// (the proposal's regular expression; m and Hz units with any SI prefix).
std::optional<double> spectral_channel_wavelength_nm(const std::string& channel, const std::string& layer = "S0");

struct ExrWriteOptions {
  bool compress = true;  // ZIP (lossless, what Blender and OpenImageIO write by default); false: uncompressed
};
// Writes a Rendering as OpenEXR 32-bit float: spectral in the JCGT layout (S0./T. channels, spectralLayoutVersion,
// emissiveUnits when `units` is set, and R,G,B preview channels in linear Rec. 709 for ordinary viewers), xyz as
// X,Y,Z, rgb as R,G,B with `chromaticities` (and `whiteLuminance` when known). Throws io_error / bad_parameter.
void write_openexr(const Rendering& image, const std::filesystem::path& file, const ExrWriteOptions& options = {});

// One spectral Rendering from N single-band images (e.g. one Blender render per band, each RGB with grey albedos
// so R = G = B): each band's value is the mean of its image's channels. All images must share one size; the
// result's `units` are `units`. Throws bad_data on a size mismatch, bad_parameter on unsorted/duplicate bands.
Rendering assemble_spectral(const std::vector<Rendering>& bands, const std::vector<double>& wavelengths_nm,
                            const std::string& units = "W.m^-2.sr^-1");

}  // namespace colorlab::verify
