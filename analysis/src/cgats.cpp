#include "colorlab/analysis/cgats.hpp"

#include "colorlab/analysis/csv.hpp"
#include "parse_util.hpp"

namespace colorlab::analysis {

namespace {

// Splits a line into whitespace-separated tokens, keeping "quoted strings" whole.
std::vector<std::string> tokenize(std::string_view line, const std::string& where) {
  std::vector<std::string> out;
  std::size_t i = 0;
  while (i < line.size()) {
    char c = line[i];
    if (c == ' ' || c == '\t' || c == '\r') {
      ++i;
      continue;
    }
    if (c == '#') break;
    if (c == '"') {
      std::size_t end = line.find('"', i + 1);
      if (end == std::string_view::npos) detail::fail(where + ": unterminated quoted string");
      out.emplace_back(line.substr(i + 1, end - i - 1));
      i = end + 1;
      continue;
    }
    std::size_t end = i;
    while (end < line.size() && line[end] != ' ' && line[end] != '\t' && line[end] != '\r') ++end;
    out.emplace_back(line.substr(i, end - i));
    i = end;
  }
  return out;
}

}  // namespace

std::optional<std::string> CgatsTable::keyword(std::string_view name) const {
  for (const auto& [k, v] : keywords)
    if (k == name) return v;
  return std::nullopt;
}

std::optional<std::size_t> CgatsTable::field_index(std::string_view name) const {
  for (std::size_t i = 0; i < fields.size(); ++i)
    if (fields[i] == name) return i;
  return std::nullopt;
}

double CgatsTable::number(std::size_t row, std::size_t field) const {
  if (row >= rows.size() || field >= fields.size())
    detail::fail(source + ": row " + std::to_string(row + 1) + " / field " + std::to_string(field) + " out of range");
  auto v = detail::to_double(rows[row][field]);
  if (!v)
    detail::fail(source + ": data row " + std::to_string(row + 1) + ", field " + fields[field] + ": '" +
                 rows[row][field] + "' is not a number");
  return *v;
}

double CgatsTable::number(std::size_t row, std::string_view field) const {
  auto idx = field_index(field);
  if (!idx) detail::fail(source + ": no field " + std::string(field));
  return number(row, *idx);
}

std::vector<CgatsTable> parse_cgats(std::string_view text, const std::string& source_name) {
  enum class State {
    header,
    format,
    data
  } state = State::header;
  std::vector<CgatsTable> tables;
  CgatsTable cur;
  cur.source = source_name;
  bool have_type = false;
  std::size_t line_no = 0;
  std::size_t pos = 0;
  auto finish_table = [&]() {
    tables.push_back(std::move(cur));
    cur = CgatsTable{};
    cur.source = source_name;
    have_type = false;
  };
  while (pos <= text.size()) {
    std::size_t nl = text.find('\n', pos);
    std::string_view line = text.substr(pos, nl == std::string_view::npos ? std::string_view::npos : nl - pos);
    pos = (nl == std::string_view::npos) ? text.size() + 1 : nl + 1;
    ++line_no;
    const std::string where = source_name + ":" + std::to_string(line_no);
    auto tok = tokenize(line, where);
    if (tok.empty()) continue;
    switch (state) {
      case State::header:
        if (!have_type) {
          cur.file_type = tok[0];
          have_type = true;
          if (tok.size() == 1) break;
          tok.erase(tok.begin());  // tolerate "CTI3  extra"
          break;
        }
        if (tok[0] == "BEGIN_DATA_FORMAT") {
          state = State::format;
          break;
        }
        if (tok[0] == "BEGIN_DATA") {
          if (cur.fields.empty()) detail::fail(where + ": BEGIN_DATA before BEGIN_DATA_FORMAT");
          state = State::data;
          break;
        }
        if (tok[0] == "KEYWORD") break;  // declares a custom keyword; its value follows on its own line
        {
          std::string value;
          for (std::size_t i = 1; i < tok.size(); ++i) value += (i > 1 ? " " : "") + tok[i];
          cur.keywords.emplace_back(tok[0], value);
        }
        break;
      case State::format:
        for (auto& t : tok) {
          if (t == "END_DATA_FORMAT") {
            state = State::header;
            break;
          }
          cur.fields.push_back(t);
        }
        break;
      case State::data:
        if (tok[0] == "END_DATA") {
          if (auto n = cur.keyword("NUMBER_OF_SETS")) {
            auto expected = detail::to_double(*n);
            // Compared as a double: converting 1e300, -1 or NaN to a count is undefined.
            if (expected && *expected != static_cast<double>(cur.rows.size()))
              detail::fail(where + ": NUMBER_OF_SETS says " + *n + " but " + std::to_string(cur.rows.size()) +
                           " data rows were read");
          }
          finish_table();
          state = State::header;
          break;
        }
        if (tok.size() != cur.fields.size())
          detail::fail(where + ": data row has " + std::to_string(tok.size()) + " values, format declares " +
                       std::to_string(cur.fields.size()) + " fields");
        cur.rows.push_back(std::move(tok));
        break;
    }
  }
  if (state == State::data) detail::fail(source_name + ": missing END_DATA");
  if (state == State::format) detail::fail(source_name + ": missing END_DATA_FORMAT");
  if (tables.empty()) detail::fail(source_name + ": no CGATS data table found");
  return tables;
}

std::vector<CgatsTable> read_cgats_all(const std::filesystem::path& path) {
  return parse_cgats(read_text_file(path), path.string());
}

CgatsTable read_cgats(const std::filesystem::path& path) { return std::move(read_cgats_all(path).front()); }

}  // namespace colorlab::analysis
