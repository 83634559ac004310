// The CSV reader (analysis/csv): a whole file's text, every cell read as a number the way the chart,
// spectral and uniformity readers read them.
#include "colorlab/analysis/csv.hpp"
#include "fuzz_support.hpp"

namespace {

using colorlab::fuzz::typed;

void one_input(const std::uint8_t* data, std::size_t size) {
  colorlab::analysis::CsvTable t;
  if (!typed("parse_csv", [&] { t = colorlab::analysis::parse_csv(colorlab::fuzz::as_text(data, size), "fuzz.csv"); })) return;
  typed("require_column", [&] { (void)t.require_column("wavelength"); });
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    if (t.rows[r].size() != t.header.size()) {
      std::fprintf(stderr, "fuzz: CSV row %zu has %zu cells, header %zu\n", r, t.rows[r].size(), t.header.size());
      std::abort();
    }
    for (std::size_t c = 0; c < t.header.size(); ++c) typed("CsvTable::number", [&] { (void)t.number(r, c); });
  }
}

}  // namespace

COLORLAB_FUZZ_TARGET("csv", one_input)
