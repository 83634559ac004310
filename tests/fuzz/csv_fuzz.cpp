// The CSV reader and writer (analysis/csv.cpp, csv_write.cpp): a whole file's text, every cell read
// as a number the way the chart, spectral and uniformity readers read them; then what was read written
// back with the writer colorlab's exports use and read again, which must give the same table — the
// writer promises parse_csv returns exactly each cell — and every number the shortest text that reads
// back to the same double.
#include <cmath>
#include <cstring>

#include "colorlab/analysis/csv.hpp"
#include "fuzz_support.hpp"

namespace {

using colorlab::fuzz::typed;
namespace an = colorlab::analysis;

[[noreturn]] void differs(const char* what, const std::string& written) {
  std::fprintf(stderr, "fuzz: CSV round trip changed the %s; written:\n%s\n", what, written.c_str());
  std::abort();
}

void one_input(const std::uint8_t* data, std::size_t size) {
  an::CsvTable t;
  if (!typed("parse_csv", [&] { t = an::parse_csv(colorlab::fuzz::as_text(data, size), "fuzz.csv"); })) return;
  typed("require_column", [&] { (void)t.require_column("wavelength"); });
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    if (t.rows[r].size() != t.header.size()) {
      std::fprintf(stderr, "fuzz: CSV row %zu has %zu cells, header %zu\n", r, t.rows[r].size(), t.header.size());
      std::abort();
    }
    for (std::size_t c = 0; c < t.header.size(); ++c) {
      double v = 0;
      if (!typed("CsvTable::number", [&] { v = t.number(r, c); })) continue;
      double back = 0;
      const std::string text = an::csv_number(v);
      if (!typed("csv_number read back", [&] { back = an::parse_csv("x\n" + text + "\n", "number").number(0, 0); })) {
        differs("a number's text", text);
      }
      if (std::memcmp(&back, &v, sizeof v) != 0 && !(std::isnan(back) && std::isnan(v))) differs("a number", text);
    }
  }
  std::string written;
  an::append_csv_row(written, t.header);
  for (const auto& row : t.rows) an::append_csv_row(written, row);
  an::CsvTable again;
  if (!typed("parse_csv of written", [&] { again = an::parse_csv(written, "written.csv"); })) differs("table (unreadable)", written);
  if (again.header != t.header) differs("header", written);
  if (again.rows != t.rows) differs("rows", written);
}

}  // namespace

COLORLAB_FUZZ_TARGET("csv", one_input)
