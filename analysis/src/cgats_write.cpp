// The writing half of cgats.hpp, through lcms2's IT8/CGATS writer. Kept apart from the reader so that
// the reader builds (and is fuzzed) without lcms2.
#include <fstream>
#include <memory>

#include <lcms2.h>

#include "colorlab/analysis/cgats.hpp"
#include "parse_util.hpp"

namespace colorlab::analysis {

namespace {

// lcms2 reports errors through its context's log handler; each write gets its own context, so
// concurrent writers (the daemon's reading threads) never see one another's message.
struct LcmsLog {
  std::string message;
};

void log_error(cmsContext ctx, cmsUInt32Number, const char* text) {
  if (auto* log = static_cast<LcmsLog*>(cmsGetContextUserData(ctx)); log && log->message.empty()) log->message = text;
}

struct ContextDeleter {
  void operator()(void* c) const { cmsDeleteContext(static_cast<cmsContext>(c)); }
};
struct It8Deleter {
  void operator()(void* h) const { cmsIT8Free(h); }
};

}  // namespace

std::string format_cgats(const CgatsTable& t) {
  LcmsLog log;
  std::unique_ptr<void, ContextDeleter> ctx(cmsCreateContext(nullptr, &log));
  if (!ctx) throw Error(ErrorClass::internal, "lcms2: cannot create a context");
  cmsSetLogErrorHandlerTHR(static_cast<cmsContext>(ctx.get()), log_error);
  std::unique_ptr<void, It8Deleter> it8(cmsIT8Alloc(static_cast<cmsContext>(ctx.get())));
  auto check = [&](cmsBool ok, const std::string& what) {
    if (!ok) detail::fail("CGATS " + t.file_type + ": lcms2 cannot write " + what + (log.message.empty() ? "" : ": " + log.message));
  };
  check(it8 != nullptr, "a table");
  cmsHANDLE h = it8.get();
  check(cmsIT8SetSheetType(h, t.file_type.empty() ? "CGATS.17" : t.file_type.c_str()), "the file type");
  for (const auto& [k, v] : t.keywords) {
    if (k == "NUMBER_OF_FIELDS" || k == "NUMBER_OF_SETS") continue;
    // Quoted, numbers too, as Argyll writes its keywords.
    check(cmsIT8SetPropertyStr(h, k.c_str(), v.c_str()), "keyword " + k);
  }
  check(cmsIT8SetPropertyDbl(h, "NUMBER_OF_FIELDS", static_cast<double>(t.fields.size())), "NUMBER_OF_FIELDS");
  for (std::size_t i = 0; i < t.fields.size(); ++i)
    check(cmsIT8SetDataFormat(h, static_cast<int>(i), t.fields[i].c_str()), "field " + t.fields[i]);
  check(cmsIT8SetPropertyDbl(h, "NUMBER_OF_SETS", static_cast<double>(t.rows.size())), "NUMBER_OF_SETS");
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    if (t.rows[r].size() != t.fields.size())
      detail::fail("CGATS " + t.file_type + ": row " + std::to_string(r + 1) + " has " + std::to_string(t.rows[r].size()) +
                   " values for " + std::to_string(t.fields.size()) + " fields");
    for (std::size_t c = 0; c < t.fields.size(); ++c)
      check(cmsIT8SetDataRowCol(h, static_cast<int>(r), static_cast<int>(c), t.rows[r][c].c_str()),
            "row " + std::to_string(r + 1) + ", field " + t.fields[c]);
  }
  cmsUInt32Number size = 0;
  check(cmsIT8SaveToMem(h, nullptr, &size), "the text");
  std::string out(size, '\0');
  check(cmsIT8SaveToMem(h, out.data(), &size), "the text");
  // lcms2 counts the terminating NUL.
  while (!out.empty() && out.back() == '\0') out.pop_back();
  return out;
}

void write_cgats(const CgatsTable& table, const std::filesystem::path& path) {
  const std::string text = format_cgats(table);
  std::ofstream f(path, std::ios::binary);
  if (!f) throw Error(ErrorClass::io_error, "cannot write CGATS file " + path.string());
  f << text;
  if (!f) throw Error(ErrorClass::io_error, "write failed for " + path.string());
}

}  // namespace colorlab::analysis
