#include "colorlab/analysis/cgats.hpp"

#include <memory>

#include <lcms2.h>

#include "colorlab/analysis/csv.hpp"
#include "parse_util.hpp"

namespace colorlab::analysis {

namespace {

// lcms2 reports errors through its context's log handler; each parse gets its own context, so
// concurrent readers (the daemon's reading threads) never see one another's message.
struct LcmsLog {
  std::string message;
};

void log_error(cmsContext ctx, cmsUInt32Number, const char* text) {
  auto* log = static_cast<LcmsLog*>(cmsGetContextUserData(ctx));
  if (!log || !log->message.empty()) return;
  log->message = text;
  // lcms2 prefixes the name of the file it was given; from memory that is empty (": Line 3, ...").
  if (log->message.rfind(": ", 0) == 0) log->message.erase(0, 2);
}

struct ContextDeleter {
  void operator()(void* c) const { cmsDeleteContext(static_cast<cmsContext>(c)); }
};
struct It8Deleter {
  void operator()(void* h) const { cmsIT8Free(h); }
};

// lcms2 numbers its tables from 0 and keeps their keywords, fields and cells as text; this copies one
// out so that the table outlives the handle and reads the same whatever wrote the file.
CgatsTable copy_table(cmsHANDLE h, const std::string& source_name, int index) {
  CgatsTable t;
  t.source = source_name;
  if (const char* type = cmsIT8GetSheetType(h)) t.file_type = type;
  char** names = nullptr;
  const auto n_props = cmsIT8EnumProperties(h, &names);
  for (cmsUInt32Number i = 0; i < n_props; ++i) {
    const char* value = cmsIT8GetProperty(h, names[i]);
    t.keywords.emplace_back(names[i], value ? value : "");
  }
  char** fields = nullptr;
  const int n_fields = cmsIT8EnumDataFormat(h, &fields);
  const std::string where = source_name + " (table " + std::to_string(index + 1) + ")";
  if (n_fields <= 0) detail::fail(where + ": no BEGIN_DATA_FORMAT fields");
  for (int i = 0; i < n_fields; ++i) t.fields.emplace_back(fields[i] ? fields[i] : "");
  const double sets = cmsIT8GetPropertyDbl(h, "NUMBER_OF_SETS");
  // Compared as a double before the conversion: converting 1e300, -1 or NaN to a count is undefined.
  if (!(sets >= 0 && sets <= 1e7)) detail::fail(where + ": NUMBER_OF_SETS is not a count");
  const auto rows = static_cast<int>(sets);
  t.rows.reserve(static_cast<std::size_t>(rows));
  for (int r = 0; r < rows; ++r) {
    std::vector<std::string> row;
    row.reserve(static_cast<std::size_t>(n_fields));
    for (int c = 0; c < n_fields; ++c) {
      const char* cell = cmsIT8GetDataRowCol(h, r, c);
      // lcms2 sizes the table by NUMBER_OF_SETS; a file with fewer rows than it says leaves holes.
      if (!cell)
        detail::fail(where + ": NUMBER_OF_SETS says " + std::to_string(rows) + " but data row " + std::to_string(r + 1) +
                     " has no value for " + t.fields[static_cast<std::size_t>(c)]);
      row.emplace_back(cell);
    }
    t.rows.push_back(std::move(row));
  }
  return t;
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

// lcms2's IT8/CGATS.17 parser (the one its writer pairs with, fuzzed upstream by OSS-Fuzz) reads the
// file; colorlab keeps only the copy of its tables. Its non-strict mode takes the keywords and fields
// ArgyllCMS invents (SPECTRAL_NORM, SPEC_380 ...) without a KEYWORD declaration, as Argyll does.
std::vector<CgatsTable> parse_cgats(std::string_view text, const std::string& source_name) {
  if (text.find_first_not_of(" \t\r\n") == std::string_view::npos) detail::fail(source_name + ": no CGATS data table found");
  LcmsLog log;
  std::unique_ptr<void, ContextDeleter> ctx(cmsCreateContext(nullptr, &log));
  if (!ctx) throw Error(ErrorClass::internal, "lcms2: cannot create a context");
  cmsSetLogErrorHandlerTHR(static_cast<cmsContext>(ctx.get()), log_error);
  // lcms2 takes a non-const buffer and a 32-bit length; it does not write to it.
  if (text.size() > 0x7fffffffu) detail::fail(source_name + ": larger than 2 GiB");
  std::string buffer(text);
  std::unique_ptr<void, It8Deleter> it8(cmsIT8LoadFromMem(static_cast<cmsContext>(ctx.get()), buffer.data(),
                                                           static_cast<cmsUInt32Number>(buffer.size())));
  if (!it8) detail::fail(source_name + ": " + (log.message.empty() ? std::string("not a CGATS file") : log.message));
  cmsHANDLE h = it8.get();
  std::vector<CgatsTable> tables;
  const auto count = cmsIT8TableCount(h);
  for (cmsUInt32Number i = 0; i < count; ++i) {
    if (cmsIT8SetTable(h, i) < 0) detail::fail(source_name + ": cannot select table " + std::to_string(i + 1));
    tables.push_back(copy_table(h, source_name, static_cast<int>(i)));
  }
  if (tables.empty()) detail::fail(source_name + ": no CGATS data table found");
  return tables;
}

std::vector<CgatsTable> read_cgats_all(const std::filesystem::path& path) {
  return parse_cgats(read_text_file(path), path.string());
}

CgatsTable read_cgats(const std::filesystem::path& path) { return std::move(read_cgats_all(path).front()); }

}  // namespace colorlab::analysis
