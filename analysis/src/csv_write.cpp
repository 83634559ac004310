// The writing half of csv.hpp: what parse_csv reads back cell for cell.
#include <array>
#include <charconv>

#include "colorlab/analysis/csv.hpp"

namespace colorlab::analysis {

std::string csv_cell(std::string_view cell) {
  // A leading '#' would make the line a comment; a trailing CR would be taken for part of a CRLF.
  const bool quote = cell.find_first_of(",\"\n\r") != std::string_view::npos || (!cell.empty() && cell.front() == '#');
  if (!quote) return std::string(cell);
  std::string out = "\"";
  for (char c : cell) {
    if (c == '"') out += '"';
    out += c;
  }
  out += '"';
  return out;
}

std::string csv_number(double v) {
  std::array<char, 64> buf{};
  auto [end, ec] = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  return std::string(buf.data(), ec == std::errc() ? end : buf.data());
}

void append_csv_row(std::string& out, const std::vector<std::string>& cells) {
  // A row of one empty cell would be a blank line, which the reader skips.
  if (cells.size() == 1 && cells.front().empty()) {
    out += "\"\"\n";
    return;
  }
  for (std::size_t i = 0; i < cells.size(); ++i) {
    if (i) out += ',';
    out += csv_cell(cells[i]);
  }
  out += '\n';
}

}  // namespace colorlab::analysis
