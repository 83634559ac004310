#pragma once
// Binary PGM (P5), 8 or 16 bit: the simplest lossless single-channel frame format dcraw (-4 -D) and
// ImageMagick write, used by `analyze averaging`.
#include <cstdint>
#include <filesystem>
#include <istream>
#include <vector>

namespace colorlab::cli::detail {

struct GrayFrame {
  std::size_t width = 0, height = 0;
  unsigned maxval = 0;
  std::vector<std::uint16_t> pixels;
};

GrayFrame read_pgm(const std::filesystem::path& path);
// The same from a stream; `path` names it in errors.
GrayFrame read_pgm(std::istream& in, const std::filesystem::path& path);

}  // namespace colorlab::cli::detail
