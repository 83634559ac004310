// Portable Float Map (PF colour, Pf grey): text header "PF\nW H\nscale\n", then 32-bit floats, rows from the
// bottom up, little-endian when scale < 0. |scale| is not applied (OpenImageIO and netpbm ignore it too).
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "colorlab/core/error.hpp"
#include "io_detail.hpp"

namespace colorlab::verify::detail {

Rendering read_pfm(const std::filesystem::path& file, std::string_view bytes) {
  const bool colour = bytes[1] == 'F';
  std::size_t pos = 2;
  auto token = [&](const char* what) {
    while (pos < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[pos]))) ++pos;
    const std::size_t start = pos;
    while (pos < bytes.size() && !std::isspace(static_cast<unsigned char>(bytes[pos]))) ++pos;
    if (start == pos) bad_data(file, std::string("PFM header ends before its ") + what + ": truncated");
    return std::string(bytes.substr(start, pos - start));
  };
  auto number = [&](const char* what) {
    const std::string t = token(what);
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    if (end == t.c_str() || *end != '\0' || !std::isfinite(v)) bad_data(file, std::string("PFM ") + what + " '" + t + "' is not a number");
    return v;
  };
  const double w = number("width"), h = number("height"), scale = number("scale");
  if (w != std::floor(w) || h != std::floor(h)) bad_data(file, "PFM width and height must be whole numbers");
  if (scale == 0) bad_data(file, "PFM scale is 0: its sign must give the byte order (negative: little-endian)");
  if (pos >= bytes.size()) bad_data(file, "PFM has no pixel data: truncated");
  ++pos;  // exactly one whitespace character separates the header from the data
  const long long width = static_cast<long long>(w), height = static_cast<long long>(h), in_ch = colour ? 3 : 1;
  check_dimensions(file, width, height, 3);
  const std::size_t need = static_cast<std::size_t>(width * height * in_ch) * 4;
  if (bytes.size() - pos != need)
    bad_data(file, "PFM header says " + std::to_string(width) + " x " + std::to_string(height) + " x " + std::to_string(in_ch) + " floats (" + std::to_string(need) + " bytes), the file holds " + std::to_string(bytes.size() - pos) + (bytes.size() - pos < need ? ": truncated" : ": inconsistent sizes"),
             bytes.size() - pos < need ? "the file is truncated" : "the header and the data disagree: the file is corrupt");
  const bool little = scale < 0;
  const bool swap = little != (std::endian::native == std::endian::little);

  Rendering r;
  r.encoding = Encoding::rgb;  // a grey map is R = G = B
  r.width = static_cast<int>(width);
  r.height = static_cast<int>(height);
  r.chromaticities = rec709_chromaticities();
  r.source_format = "pfm";
  r.pixels.resize(static_cast<std::size_t>(width * height * 3));
  const char* data = bytes.data() + pos;
  for (long long row = 0; row < height; ++row) {
    float* out = r.pixels.data() + static_cast<std::size_t>((height - 1 - row) * width * 3);
    for (long long i = 0; i < width * in_ch; ++i) {
      std::uint32_t u;
      std::memcpy(&u, data + static_cast<std::size_t>(row * width * in_ch + i) * 4, 4);
      if (swap) u = __builtin_bswap32(u);
      float v;
      std::memcpy(&v, &u, 4);
      if (colour)
        out[i] = v;
      else
        out[i * 3] = out[i * 3 + 1] = out[i * 3 + 2] = v;
    }
  }
  check_values(r, file, {"R", "G", "B"});
  return r;
}

}  // namespace colorlab::verify::detail
