// Radiance RGBE/XYZE (.hdr, .pic), after Greg Ward's format as Radiance writes and reads it (src/common/color.c,
// header.c, resolu.c): a text header ending in an empty line, a resolution string, then scanlines either flat
// (4 bytes a pixel, with the old 1,1,1,n repeat codes) or new-style run-length encoded per component.
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "colorlab/core/error.hpp"
#include "io_detail.hpp"

namespace colorlab::verify::detail {

namespace {

struct Axis {
  bool is_y = true;
  bool plus = false;
  long long size = 0;
};

bool parse_axis(std::istringstream& in, Axis& a) {
  std::string sign;
  long long n = 0;
  if (!(in >> sign >> n) || sign.size() != 2 || (sign[0] != '+' && sign[0] != '-') || (sign[1] != 'X' && sign[1] != 'Y'))
    return false;
  a.plus = sign[0] == '+';
  a.is_y = sign[1] == 'Y';
  a.size = n;
  return true;
}

}  // namespace

Rendering read_rgbe(const std::filesystem::path& file, std::string_view bytes) {
  std::size_t pos = 0;
  auto next_line = [&](const char* where) {
    const std::size_t nl = bytes.find('\n', pos);
    if (nl == std::string_view::npos) bad_data(file, std::string("RGBE header ends before ") + where + ": truncated or not an RGBE file");
    std::string line(bytes.substr(pos, nl - pos));
    pos = nl + 1;
    return line;
  };
  std::string format;
  double exposure = 1.0;
  std::optional<Chromaticities> primaries;
  for (int n = 0;; ++n) {
    std::string line = next_line("its blank line");
    if (n == 0) continue;  // "#?RADIANCE" or another program's "#?NAME"
    if (line.empty()) break;
    if (line.rfind("FORMAT=", 0) == 0) {
      format = line.substr(7);
    } else if (line.rfind("EXPOSURE=", 0) == 0) {
      // Radiance multiplies every EXPOSURE line into the pixels' scale.
      char* end = nullptr;
      const double e = std::strtod(line.c_str() + 9, &end);
      if (end == line.c_str() + 9 || !(e > 0) || !std::isfinite(e))
        bad_data(file, "header line " + std::to_string(n + 1) + ": EXPOSURE '" + line.substr(9) + "' is not a positive number");
      exposure *= e;
    } else if (line.rfind("PRIMARIES=", 0) == 0) {
      std::istringstream in(line.substr(10));
      Chromaticities c{};
      for (auto& p : c)
        if (!(in >> p[0] >> p[1])) bad_data(file, "header line " + std::to_string(n + 1) + ": PRIMARIES needs 8 numbers");
      primaries = c;
    }
  }
  Encoding encoding;
  if (format.empty() || format == "32-bit_rle_rgbe")
    encoding = Encoding::rgb;
  else if (format == "32-bit_rle_xyze")
    encoding = Encoding::xyz;
  else
    bad_data(file, "FORMAT=" + format + " is neither 32-bit_rle_rgbe nor 32-bit_rle_xyze",
             "only Radiance's two pixel encodings are images of light");

  const std::string res = next_line("its resolution line");
  std::istringstream rin(res);
  Axis major, minor;
  if (!parse_axis(rin, major) || !parse_axis(rin, minor) || major.is_y == minor.is_y)
    bad_data(file, "resolution line '" + res + "' is not of the form -Y H +X W", "the header is corrupt");
  const long long width = major.is_y ? minor.size : major.size;
  const long long height = major.is_y ? major.size : minor.size;
  check_dimensions(file, width, height, 3);

  Rendering r;
  r.encoding = encoding;
  r.width = static_cast<int>(width);
  r.height = static_cast<int>(height);
  r.source_format = "rgbe";
  if (encoding == Encoding::rgb) {
    r.chromaticities_from_file = primaries.has_value();
    r.chromaticities = primaries ? *primaries : radiance_chromaticities();
  }
  r.pixels.resize(static_cast<std::size_t>(width * height * 3));

  const long long lines = major.size, length = minor.size;
  std::vector<unsigned char> scan(static_cast<std::size_t>(length) * 4);
  auto byte_at = [&](long long line) -> unsigned char {
    if (pos >= bytes.size())
      bad_data(file, "pixel data ends in scanline " + std::to_string(line) + " of " + std::to_string(lines) + ": truncated",
               "write the file again");
    return static_cast<unsigned char>(bytes[pos++]);
  };
  for (long long s = 0; s < lines; ++s) {
    const bool rle = length >= 8 && length < 0x8000 && pos + 4 <= bytes.size() && bytes[pos] == 2 && bytes[pos + 1] == 2 &&
                     !(static_cast<unsigned char>(bytes[pos + 2]) & 0x80);
    if (rle) {
      const long long stated = (static_cast<unsigned char>(bytes[pos + 2]) << 8) | static_cast<unsigned char>(bytes[pos + 3]);
      if (stated != length)
        bad_data(file, "scanline " + std::to_string(s) + " says it is " + std::to_string(stated) + " pixels long, the header " +
                           std::to_string(length));
      pos += 4;
      for (int comp = 0; comp < 4; ++comp) {
        for (long long i = 0; i < length;) {
          unsigned count = byte_at(s);
          const bool run = count > 128;
          if (run) count -= 128;
          if (count == 0 || i + count > length)
            bad_data(file, "scanline " + std::to_string(s) + " component " + std::to_string(comp) + ": a run of " +
                               std::to_string(count) + " at pixel " + std::to_string(i) + " overruns its " +
                               std::to_string(length) + " pixels");
          if (run) {
            const unsigned char v = byte_at(s);
            for (unsigned k = 0; k < count; ++k) scan[static_cast<std::size_t>(i++) * 4 + comp] = v;
          } else {
            for (unsigned k = 0; k < count; ++k) scan[static_cast<std::size_t>(i++) * 4 + comp] = byte_at(s);
          }
        }
      }
    } else {
      // Flat pixels; (1,1,1,n) repeats the previous pixel n << shift times (Radiance's old run-length scheme).
      int shift = 0;
      for (long long i = 0; i < length;) {
        unsigned char px[4];
        for (auto& b : px) b = byte_at(s);
        if (px[0] == 1 && px[1] == 1 && px[2] == 1) {
          if (i == 0) bad_data(file, "scanline " + std::to_string(s) + " starts with a repeat code");
          const long long count = static_cast<long long>(px[3]) << shift;
          if (i + count > length)
            bad_data(file, "scanline " + std::to_string(s) + ": a repeat of " + std::to_string(count) + " at pixel " +
                               std::to_string(i) + " overruns its " + std::to_string(length) + " pixels");
          for (long long k = 0; k < count; ++k, ++i)
            for (int c = 0; c < 4; ++c) scan[static_cast<std::size_t>(i) * 4 + c] = scan[static_cast<std::size_t>(i - 1) * 4 + c];
          shift += 8;
        } else {
          for (int c = 0; c < 4; ++c) scan[static_cast<std::size_t>(i) * 4 + c] = px[c];
          ++i;
          shift = 0;
        }
      }
    }
    // Radiance decodes to the centre of the mantissa's bin, (m + 0.5)·2^(e−136), and divides out EXPOSURE.
    const long long row_or_col = major.plus == major.is_y ? lines - 1 - s : s;
    for (long long i = 0; i < length; ++i) {
      const long long along = minor.plus == minor.is_y ? length - 1 - i : i;
      const long long x = major.is_y ? along : row_or_col;
      const long long y = major.is_y ? row_or_col : along;
      float* out = r.pixels.data() + static_cast<std::size_t>(y * width + x) * 3;
      const unsigned char* px = &scan[static_cast<std::size_t>(i) * 4];
      if (px[3] == 0) {
        out[0] = out[1] = out[2] = 0.0f;
      } else {
        const double f = std::ldexp(1.0, px[3] - 136) / exposure;
        for (int c = 0; c < 3; ++c) out[c] = static_cast<float>((px[c] + 0.5) * f);
      }
    }
  }
  if (pos != bytes.size())
    bad_data(file, std::to_string(bytes.size() - pos) + " bytes after the last scanline",
             "the resolution line and the pixel data disagree: the file is corrupt");
  check_values(r, file, encoding == Encoding::rgb ? std::vector<std::string>{"R", "G", "B"} : std::vector<std::string>{"X", "Y", "Z"});
  return r;
}

}  // namespace colorlab::verify::detail
