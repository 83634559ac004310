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

// One record from `pos` (at a record's first character) to just past its line end. A quoted cell may span
// lines; `line` follows every line feed consumed.
class RecordReader {
 public:
  RecordReader(std::string_view text, const std::string& source) : text_(text), source_(source) {}

  bool at_end() const { return pos_ >= text_.size(); }
  std::size_t line() const { return line_; }

  // Blank lines and '#' comment lines between records.
  bool skip_ignorable_line() {
    std::size_t eol = text_.find('\n', pos_);
    std::string_view rest = text_.substr(pos_, eol == std::string_view::npos ? std::string_view::npos : eol - pos_);
    if (!(rest.empty() || rest == "\r" || rest.front() == '#')) return false;
    pos_ = eol == std::string_view::npos ? text_.size() : eol + 1;
    ++line_;
    return true;
  }

  std::vector<std::string> record() {
    std::vector<std::string> cells;
    for (;;) {
      cells.push_back(at(pos_) == '"' ? quoted_cell() : plain_cell());
      if (at_end()) break;
      if (text_[pos_] == ',') {
        ++pos_;
        continue;
      }
      ++pos_;  // the line feed
      ++line_;
      break;
    }
    return cells;
  }

 private:
  char at(std::size_t i) const { return i < text_.size() ? text_[i] : '\0'; }

  std::string plain_cell() {
    std::size_t end = pos_;
    while (end < text_.size() && text_[end] != ',' && text_[end] != '\n') ++end;
    std::string cell(text_.substr(pos_, end - pos_));
    pos_ = end;
    if ((at_end() || text_[pos_] == '\n') && !cell.empty() && cell.back() == '\r') cell.pop_back();
    return cell;
  }

  std::string quoted_cell() {
    const std::size_t opened = line_;
    std::string cell;
    ++pos_;
    for (;;) {
      if (at_end()) detail::fail(source_ + ":" + std::to_string(opened) + ": quoted cell is never closed");
      char c = text_[pos_++];
      if (c == '"') {
        if (at(pos_) != '"') break;
        ++pos_;
      } else if (c == '\n') {
        ++line_;
      }
      cell += c;
    }
    if (at(pos_) == '\r' && (pos_ + 1 >= text_.size() || text_[pos_ + 1] == '\n')) ++pos_;
    if (!at_end() && text_[pos_] != ',' && text_[pos_] != '\n')
      detail::fail(source_ + ":" + std::to_string(line_) + ": text after the closing quote of a cell",
                   "a quote inside a quoted cell is written twice (\"\")");
    return cell;
  }

  std::string_view text_;
  const std::string& source_;
  std::size_t pos_ = 0;
  std::size_t line_ = 1;
};

void drop_trailing_empty(std::vector<std::string>& cells, std::size_t keep) {
  while (cells.size() > keep && cells.back().empty()) cells.pop_back();
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

std::size_t CsvTable::line_of(std::size_t row) const { return row < row_lines.size() ? row_lines[row] : row + 2; }

std::optional<double> CsvTable::try_number(std::size_t row, std::size_t col) const {
  if (row >= rows.size() || col >= rows[row].size()) return std::nullopt;
  return detail::to_double(rows[row][col]);
}

double CsvTable::number(std::size_t row, std::size_t col) const {
  if (row >= rows.size() || col >= rows[row].size()) detail::fail(source + ": cell out of range");
  auto v = try_number(row, col);
  if (!v) {
    const std::string name = col < header.size() ? "column '" + header[col] + "'" : "column " + std::to_string(col + 1);
    detail::fail(source + ":" + std::to_string(line_of(row)) + ", " + name + ": '" + rows[row][col] + "' is not a number");
  }
  return *v;
}

CsvTable parse_csv(std::string_view text, const std::string& source_name, const CsvOptions& options) {
  CsvTable t;
  t.source = source_name;
  RecordReader reader(text, t.source);
  bool have_header = false;
  while (!reader.at_end()) {
    if (reader.skip_ignorable_line()) continue;
    const std::size_t line = reader.line();
    auto cells = reader.record();
    // Spreadsheets often end every line with a comma; an empty last cell beyond the header is not data.
    if (options.header && !have_header) {
      drop_trailing_empty(cells, 0);
      if (cells.empty()) continue;
      t.header = std::move(cells);
      have_header = true;
      continue;
    }
    const std::size_t width = options.header ? t.header.size() : (t.rows.empty() ? 1 : t.rows.front().size());
    drop_trailing_empty(cells, width);
    if (!options.header && t.rows.empty()) {
      if (cells.size() == 1 && cells.front().empty()) continue;
    } else if (cells.size() != width) {
      detail::fail(source_name + ":" + std::to_string(line) + ": " + std::to_string(cells.size()) + " cells, " +
                   (options.header ? "header has " : "first row has ") + std::to_string(width));
    }
    t.rows.push_back(std::move(cells));
    t.row_lines.push_back(line);
  }
  if (options.header && !have_header) detail::fail(source_name + ": empty CSV file (no header row)");
  return t;
}

CsvTable read_csv(const std::filesystem::path& path, const CsvOptions& options) {
  return parse_csv(read_text_file(path), path.string(), options);
}

std::vector<std::string> parse_csv_row(std::string_view text, const std::string& source_name) {
  CsvTable t = parse_csv(text, source_name, {.header = false});
  if (t.rows.size() != 1)
    detail::fail(source_name + ": expected one row of comma-separated values, got " + std::to_string(t.rows.size()));
  return std::move(t.rows.front());
}

}  // namespace colorlab::analysis
