#pragma once
// Comma-separated tables (RFC 4180, as the team's shared data set, spreadsheets and colorlab's own exports
// write them): the project's one CSV reader, and the writer whose output it reads back exactly.
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace colorlab::analysis {

struct CsvTable {
  std::vector<std::string> header;             // empty when read without a header row
  std::vector<std::vector<std::string>> rows;  // each row has header.size() cells (or the first row's count)
  std::vector<std::size_t> row_lines;          // the file line each row starts on, for messages
  std::string source;

  std::size_t columns() const { return header.empty() ? (rows.empty() ? 0 : rows.front().size()) : header.size(); }
  std::optional<std::size_t> column(std::string_view name) const;
  std::size_t require_column(std::string_view name) const;                   // throws Error(bad_data)
  double number(std::size_t row, std::size_t col) const;                     // throws Error(bad_data) naming file:line
  std::optional<double> try_number(std::size_t row, std::size_t col) const;  // nullopt: not a number
  std::size_t line_of(std::size_t row) const;
};

struct CsvOptions {
  // Without a header, every row is data (a grid of numbers) and all rows must have the first row's width.
  bool header = true;
};

// Cells may be quoted ("a, b", "say ""hi""", line breaks inside quotes); lines starting with '#' and blank
// lines are skipped; CRLF and LF both end a line. Throws Error(bad_data) naming source:line for a row of the
// wrong width, an unterminated quote or text after a closing quote.
CsvTable parse_csv(std::string_view text, const std::string& source_name, const CsvOptions& options = {});
CsvTable read_csv(const std::filesystem::path& path, const CsvOptions& options = {});
// Exactly one row without a header, e.g. a list given on the command line ("x1,y1,x2,y2").
std::vector<std::string> parse_csv_row(std::string_view text, const std::string& source_name);

// Reads a whole file; throws Error(io_error) naming the path when it cannot.
std::string read_text_file(const std::filesystem::path& path);

// Writing: a cell quoted only when it must be (comma, quote, line break, leading '#' or surrounding spaces),
// so that parse_csv returns exactly `cell`.
std::string csv_cell(std::string_view cell);
// The shortest text that parses back to exactly `v` (std::to_chars); "nan"/"inf" are written as such.
std::string csv_number(double v);
// Appends one row and a line feed to `out`.
void append_csv_row(std::string& out, const std::vector<std::string>& cells);

}  // namespace colorlab::analysis
