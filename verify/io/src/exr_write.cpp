// Rendering → OpenEXR, the writer the tests, the bench and the Blender band assembly use.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <ImfStandardAttributes.h>
#include <ImfStringAttribute.h>

#include <array>
#include <cmath>

#include "colorlab/core/error.hpp"
#include "colorlab/verify/rendering_xyz.hpp"
#include "exr_threads.hpp"
#include "io_detail.hpp"

namespace colorlab::verify {

namespace {

Matrix3 inverse(const Matrix3& m) {
  const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                     m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  Matrix3 r{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      // cofactor (j, i) / det
      const int r0 = (j + 1) % 3, r1 = (j + 2) % 3, c0 = (i + 1) % 3, c1 = (i + 2) % 3;
      r[i][j] = (m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]) / det;
    }
  return r;
}

// Linear Rec. 709 preview of a spectral image for ordinary viewers: emissive in cd/m², reflective relative to
// the perfect reflector under the equal-energy light (Y = 1).
std::vector<float> preview_rgb(const Rendering& im) {
  std::vector<float> xyz;
  if (!im.reflective) {
    xyz = to_xyz(im).pixels;
  } else {
    const auto w = band_cmf_weights(im.wavelengths_nm);
    double ysum = 0;
    for (const auto& b : w) ysum += b[1];
    const std::size_t n = static_cast<std::size_t>(im.width) * static_cast<std::size_t>(im.height);
    const std::size_t c = w.size();
    xyz.assign(n * 3, 0.0f);
    for (std::size_t p = 0; p < n; ++p)
      for (std::size_t b = 0; b < c; ++b)
        for (int k = 0; k < 3; ++k) xyz[p * 3 + k] += static_cast<float>(w[b][k] / ysum * im.pixels[p * c + b]);
  }
  const Matrix3 m = inverse(rgb_to_xyz_matrix(rec709_chromaticities()));
  for (std::size_t p = 0; p < xyz.size(); p += 3) {
    const double X = xyz[p], Y = xyz[p + 1], Z = xyz[p + 2];
    for (int k = 0; k < 3; ++k) xyz[p + k] = static_cast<float>(m[k][0] * X + m[k][1] * Y + m[k][2] * Z);
  }
  return xyz;
}

void write(const Rendering& im, const std::filesystem::path& file, const ExrWriteOptions& options) {
  const int c = im.channels();
  if (im.width <= 0 || im.height <= 0 || c <= 0 ||
      im.pixels.size() != static_cast<std::size_t>(im.width) * static_cast<std::size_t>(im.height) * static_cast<std::size_t>(c))
    throw Error(ErrorClass::bad_parameter, "cannot write " + file.string() + ": the rendering's pixels (" +
                                               std::to_string(im.pixels.size()) + " floats) do not match " +
                                               std::to_string(im.width) + " x " + std::to_string(im.height) + " x " +
                                               std::to_string(c));
  Imf::Header header(im.width, im.height);
  header.compression() = options.compress ? Imf::ZIP_COMPRESSION : Imf::NO_COMPRESSION;
  std::vector<std::string> names;
  switch (im.encoding) {
    case Encoding::spectral:
      for (double nm : im.wavelengths_nm) names.push_back(spectral_channel_name(nm, im.reflective));
      header.insert("spectralLayoutVersion", Imf::StringAttribute("1.0"));
      if (!im.units.empty()) header.insert(im.reflective ? "reflectiveUnits" : "emissiveUnits", Imf::StringAttribute(im.units));
      break;
    case Encoding::xyz:
      names = {"X", "Y", "Z"};
      break;
    case Encoding::rgb: {
      names = {"R", "G", "B"};
      const auto& ch = im.chromaticities;
      Imf::addChromaticities(header, Imf::Chromaticities({static_cast<float>(ch[0][0]), static_cast<float>(ch[0][1])},
                                                         {static_cast<float>(ch[1][0]), static_cast<float>(ch[1][1])},
                                                         {static_cast<float>(ch[2][0]), static_cast<float>(ch[2][1])},
                                                         {static_cast<float>(ch[3][0]), static_cast<float>(ch[3][1])}));
      break;
    }
  }
  if (im.encoding != Encoding::spectral && im.white_luminance_cd_m2)
    Imf::addWhiteLuminance(header, static_cast<float>(*im.white_luminance_cd_m2));

  const std::size_t xs = sizeof(float) * static_cast<std::size_t>(c);
  const std::size_t ys = xs * static_cast<std::size_t>(im.width);
  Imf::FrameBuffer fb;
  // OpenEXR's slices take a non-const pointer though writing only reads them.
  char* base = const_cast<char*>(reinterpret_cast<const char*>(im.pixels.data()));
  for (std::size_t k = 0; k < names.size(); ++k) {
    header.channels().insert(names[k], Imf::Channel(Imf::FLOAT));
    fb.insert(names[k], Imf::Slice(Imf::FLOAT, base + k * sizeof(float), xs, ys));
  }
  std::vector<float> preview;
  if (im.encoding == Encoding::spectral) {
    preview = preview_rgb(im);
    const char* rgb[] = {"R", "G", "B"};
    for (std::size_t k = 0; k < 3; ++k) {
      header.channels().insert(rgb[k], Imf::Channel(Imf::FLOAT));
      fb.insert(rgb[k], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(preview.data()) + k * sizeof(float), 3 * sizeof(float),
                                   3 * sizeof(float) * static_cast<std::size_t>(im.width)));
    }
    Imf::addChromaticities(header, Imf::Chromaticities());  // the preview is Rec. 709
  }
  Imf::OutputFile out(file.c_str(), header, detail::exr_threads());
  out.setFrameBuffer(fb);
  out.writePixels(im.height);
}

}  // namespace

void write_openexr(const Rendering& image, const std::filesystem::path& file, const ExrWriteOptions& options) {
  try {
    write(image, file, options);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(ErrorClass::io_error, file.string() + ": cannot write OpenEXR: " + e.what(),
                "check that the directory exists, is writable and has space");
  }
}

}  // namespace colorlab::verify
