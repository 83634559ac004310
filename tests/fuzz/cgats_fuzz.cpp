// The CGATS.17 reader (analysis/cgats): a whole file's text, every table, every keyword and every
// cell read as a number the way the chart and spectral readers read them.
#include "colorlab/analysis/cgats.hpp"
#include "fuzz_support.hpp"

namespace {

using colorlab::fuzz::typed;

void one_input(const std::uint8_t* data, std::size_t size) {
  std::vector<colorlab::analysis::CgatsTable> tables;
  if (!typed("parse_cgats", [&] { tables = colorlab::analysis::parse_cgats(colorlab::fuzz::as_text(data, size), "fuzz.ti3"); })) {
    return;
  }
  for (const auto& t : tables) {
    (void)t.keyword("NUMBER_OF_SETS");
    for (std::size_t r = 0; r < t.rows.size(); ++r) {
      for (std::size_t f = 0; f < t.fields.size(); ++f) typed("CgatsTable::number", [&] { (void)t.number(r, f); });
      typed("CgatsTable::number(name)", [&] { (void)t.number(r, "XYZ_Y"); });
    }
  }
}

}  // namespace

COLORLAB_FUZZ_TARGET("cgats", one_input)
