#include "colorlab/analysis/csv.hpp"

#include <fstream>
#include <sstream>

#include "parse_util.hpp"

namespace colorlab::analysis {

std::string read_text_file(const std::filesystem::path& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw Error(ErrorClass::io_error, "cannot open " + path.string() + " for reading", "check the path and permissions");
  std::ostringstream ss;
  ss << f.rdbuf();
  if (f.bad()) throw Error(ErrorClass::io_error, "read error on " + path.string());
  return ss.str();
}

namespace {
std::vector<std::string> split_csv_line(std::string_view line) {
  std::vector<std::string> cells;
  std::string cell;
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        cell += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        cell += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      cells.push_back(std::move(cell));
      cell.clear();
    } else if (c != '\r') {
      cell += c;
    }
  }
  cells.push_back(std::move(cell));
  return cells;
}
}  // namespace

std::optional<std::size_t> CsvTable::column(std::string_view name) const {
  for (std::size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return i;
  return std::nullopt;
}

std::size_t CsvTable::require_column(std::string_view name) const {
  auto c = column(name);
  if (!c) detail::fail(source + ": no column '" + std::string(name) + "'");
  return *c;
}

double CsvTable::number(std::size_t row, std::size_t col) const {
  if (row >= rows.size() || col >= header.size()) detail::fail(source + ": cell out of range");
  auto v = detail::to_double(rows[row][col]);
  if (!v)
    detail::fail(source + ":" + std::to_string(row + 2) + ", column '" + header[col] + "': '" + rows[row][col] +
                 "' is not a number");
  return *v;
}

CsvTable parse_csv(std::string_view text, const std::string& source_name) {
  CsvTable t;
  t.source = source_name;
  std::size_t pos = 0, line_no = 0;
  while (pos < text.size()) {
    std::size_t nl = text.find('\n', pos);
    std::string_view line = text.substr(pos, nl == std::string_view::npos ? std::string_view::npos : nl - pos);
    pos = nl == std::string_view::npos ? text.size() : nl + 1;
    ++line_no;
    if (line.empty() || line == "\r" || line.front() == '#') continue;
    auto cells = split_csv_line(line);
    // Spreadsheets often end every line with a comma; an empty last cell beyond the header is not data.
    if (t.header.empty()) {
      while (!cells.empty() && cells.back().empty()) cells.pop_back();
      if (cells.empty()) continue;
      t.header = std::move(cells);
      continue;
    }
    while (cells.size() > t.header.size() && cells.back().empty()) cells.pop_back();
    if (cells.size() != t.header.size())
      detail::fail(source_name + ":" + std::to_string(line_no) + ": " + std::to_string(cells.size()) +
                   " cells, header has " + std::to_string(t.header.size()));
    t.rows.push_back(std::move(cells));
  }
  if (t.header.empty()) detail::fail(source_name + ": empty CSV file (no header row)");
  return t;
}

CsvTable read_csv(const std::filesystem::path& path) { return parse_csv(read_text_file(path), path.string()); }

}  // namespace colorlab::analysis
