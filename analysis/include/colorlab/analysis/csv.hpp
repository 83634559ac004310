#pragma once
// Comma-separated tables with one header row, as the team's shared data set and spreadsheets write them.
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace colorlab::analysis {

struct CsvTable {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;  // each row has header.size() cells
  std::string source;

  std::optional<std::size_t> column(std::string_view name) const;
  std::size_t require_column(std::string_view name) const;  // throws Error(bad_data)
  double number(std::size_t row, std::size_t col) const;     // throws Error(bad_data) naming file:line
};

CsvTable parse_csv(std::string_view text, const std::string& source_name);
CsvTable read_csv(const std::filesystem::path& path);

// Reads a whole file; throws Error(io_error) naming the path when it cannot.
std::string read_text_file(const std::filesystem::path& path);

}  // namespace colorlab::analysis
