#pragma once
// CGATS.17 text files as ArgyllCMS (.ti3, .cie, .sp) and colord (.cmf, .sp) write them.
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace colorlab::analysis {

struct CgatsTable {
  std::string file_type;                                      // first line: "CTI3", "SPECT", "CMF", "CGATS.17" ...
  std::vector<std::pair<std::string, std::string>> keywords;  // in file order, quotes removed
  std::vector<std::string> fields;                            // BEGIN_DATA_FORMAT names
  std::vector<std::vector<std::string>> rows;                 // BEGIN_DATA values, one entry per field
  std::string source;                                         // file name for error messages

  std::optional<std::string> keyword(std::string_view name) const;
  std::optional<std::size_t> field_index(std::string_view name) const;
  // Throws Error(bad_data) naming file, row and field when the field is missing or not a number.
  double number(std::size_t row, std::string_view field) const;
  double number(std::size_t row, std::size_t field) const;
};

// All tables of a file (Argyll .ti3 may carry a second calibration table).
std::vector<CgatsTable> parse_cgats(std::string_view text, const std::string& source_name);
std::vector<CgatsTable> read_cgats_all(const std::filesystem::path& path);
// The first table; throws Error(io_error) if unreadable, Error(bad_data) if malformed.
CgatsTable read_cgats(const std::filesystem::path& path);

// Written by lcms2's IT8/CGATS writer (cgats_write.cpp). Cells are written as given: ArgyllCMS types a
// field it does not know (SPEC_*) by its values, so reals must carry their decimal point.
// Throws Error(bad_data) for a row of the wrong width or what lcms2 refuses.
std::string format_cgats(const CgatsTable& table);
void write_cgats(const CgatsTable& table, const std::filesystem::path& path);

}  // namespace colorlab::analysis
