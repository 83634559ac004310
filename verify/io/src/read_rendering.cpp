#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>

#include "colorlab/core/error.hpp"
#include "io_detail.hpp"

namespace colorlab::verify {

namespace detail {

void bad_data(const std::filesystem::path& file, const std::string& what, const std::string& hint) {
  throw Error(ErrorClass::bad_data, file.string() + ": " + what, hint);
}

void check_dimensions(const std::filesystem::path& file, long long width, long long height, long long channels) {
  if (width <= 0 || height <= 0)
    bad_data(file, "image size " + std::to_string(width) + " x " + std::to_string(height) + " is not positive");
  // 2^31 floats (8 GiB) is far beyond any rendering this compares; a header claiming more is corrupt or hostile.
  constexpr long long kMaxFloats = 1LL << 31;
  if (width > kMaxFloats || height > kMaxFloats || channels > 4096 || width * height > kMaxFloats / channels)
    bad_data(file, "image size " + std::to_string(width) + " x " + std::to_string(height) + " x " + std::to_string(channels) + " channels exceeds 2^31 values",
             "a header this large is corrupt; crop or split the rendering");
}

}  // namespace detail

namespace {

std::string read_all(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(ErrorClass::io_error, file.string() + ": cannot open for reading", "check the path and permissions");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw Error(ErrorClass::io_error, file.string() + ": read failed");
  return bytes;
}

}  // namespace

Rendering read_rendering(const std::filesystem::path& file) {
  char magic[4] = {};
  {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw Error(ErrorClass::io_error, file.string() + ": cannot open for reading", "check the path and permissions");
    in.read(magic, 4);
    if (in.gcount() < 4) detail::bad_data(file, "file is " + std::to_string(in.gcount()) + " bytes: too short for any image format");
  }
  // OpenEXR's magic number 20000630 little-endian; the EXR reader streams the file itself (it can be 300 MB).
  if (static_cast<unsigned char>(magic[0]) == 0x76 && static_cast<unsigned char>(magic[1]) == 0x2f &&
      static_cast<unsigned char>(magic[2]) == 0x31 && static_cast<unsigned char>(magic[3]) == 0x01)
    return detail::read_openexr(file);
  if (magic[0] == '#' && magic[1] == '?') return detail::read_rgbe(file, read_all(file));
  if (magic[0] == 'P' && (magic[1] == 'F' || magic[1] == 'f') && std::isspace(static_cast<unsigned char>(magic[2])))
    return detail::read_pfm(file, read_all(file));
  throw Error(ErrorClass::unsupported, file.string() + ": not an OpenEXR, Radiance RGBE or PFM file (by its first bytes)",
              "convert the rendering to OpenEXR (spectral JCGT layout, XYZ or RGB), .hdr or .pfm");
}

}  // namespace colorlab::verify
