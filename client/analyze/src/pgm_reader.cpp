#include "pgm_reader.hpp"

#include <algorithm>
#include <fstream>
#include <string>

#include "colorlab/core/error.hpp"

namespace colorlab::cli::detail {

namespace {
std::string token(std::istream& in) {
  std::string t;
  char c;
  while (in.get(c)) {
    if (c == '#') {
      std::string skip;
      std::getline(in, skip);
      continue;
    }
    if (std::isspace(static_cast<unsigned char>(c))) {
      if (!t.empty()) break;
      continue;
    }
    t += c;
  }
  return t;
}
}  // namespace

GrayFrame read_pgm(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorClass::io_error, "cannot open frame " + path.string());
  return read_pgm(in, path);
}

GrayFrame read_pgm(std::istream& in, const std::filesystem::path& path) {
  if (token(in) != "P5") throw Error(ErrorClass::bad_data, path.string() + ": not a binary PGM (P5) file");
  GrayFrame f;
  try {
    f.width = std::stoul(token(in));
    f.height = std::stoul(token(in));
    f.maxval = static_cast<unsigned>(std::stoul(token(in)));
  } catch (const std::exception&) {
    throw Error(ErrorClass::bad_data, path.string() + ": malformed PGM header");
  }
  // Divided, not multiplied: width × height of two huge numbers wraps to a small one.
  constexpr std::size_t kMaxPixels = std::size_t{1} << 28;
  if (f.width == 0 || f.height == 0 || f.maxval == 0 || f.maxval > 65535 || f.width > kMaxPixels ||
      f.height > kMaxPixels / f.width)
    throw Error(ErrorClass::bad_data, path.string() + ": implausible PGM size or maxval");
  const std::size_t n = f.width * f.height, bytes = f.maxval > 255 ? 2 : 1;
  // Grown as the data arrives, so a short file with a large header costs what it holds, not 512 MiB.
  std::vector<unsigned char> raw;
  while (raw.size() < n * bytes) {
    const std::size_t have = raw.size(), want = std::min<std::size_t>(std::size_t{1} << 20, n * bytes - have);
    raw.resize(have + want);
    in.read(reinterpret_cast<char*>(raw.data() + have), static_cast<std::streamsize>(want));
    if (in.gcount() != static_cast<std::streamsize>(want))
      throw Error(ErrorClass::bad_data, path.string() + ": truncated PGM data");
  }
  f.pixels.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    f.pixels[i] = bytes == 2 ? static_cast<std::uint16_t>(raw[2 * i] << 8 | raw[2 * i + 1]) : raw[i];  // PGM is big-endian
  return f;
}

}  // namespace colorlab::cli::detail
