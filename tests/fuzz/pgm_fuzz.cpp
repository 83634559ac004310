// The binary PGM reader of `colorlab analyze averaging` (client/analyze pgm_reader.cpp): a whole
// file's bytes. An accepted frame must hold exactly width × height pixels, since the averaging
// indexes them by row and column.
#include <sstream>

#include "fuzz_support.hpp"
#include "pgm_reader.hpp"

namespace {

void one_input(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(colorlab::fuzz::as_text(data, size)), std::ios::binary);
  colorlab::cli::detail::GrayFrame f;
  if (!colorlab::fuzz::typed("read_pgm", [&] { f = colorlab::cli::detail::read_pgm(in, "fuzz.pgm"); })) return;
  if (f.width == 0 || f.height == 0 || f.pixels.size() / f.width != f.height || f.pixels.size() % f.width != 0) {
    std::fprintf(stderr, "fuzz: PGM of %zu x %zu accepted with %zu pixels\n", f.width, f.height, f.pixels.size());
    std::abort();
  }
}

}  // namespace

COLORLAB_FUZZ_TARGET("pgm", one_input)
