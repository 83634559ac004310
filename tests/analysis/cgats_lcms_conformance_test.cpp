// colorlab's CGATS reader against lcms2's IT8 parser, an independent implementation, on every CGATS file
// that ArgyllCMS and colord ship (charts, references, spectra, observers) and the project's test data:
// the same file type, fields, cells and keywords. lcms2 reads only here, on trusted files: Debian 12's
// 2.14 crashes on malformed input (our fuzzer found a SIGBUS in cmsIT8LoadFromMem in minutes, kept in
// tests/fuzz/regressions/cgats/; upstream mm2/Little-CMS #329, #333, #337, #373), so the product keeps
// its own, fuzzed reader.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <map>
#include <memory>
#include <vector>

#include <gtest/gtest.h>
#include <lcms2.h>

#include "colorlab/analysis/cgats.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
namespace ca = colorlab::analysis;

namespace {

struct It8Free {
  void operator()(void* h) const { cmsIT8Free(h); }
};

// What lcms2 reads from the file, table by table; nullopt when it refuses the file.
std::optional<std::vector<ca::CgatsTable>> read_with_lcms2(const fs::path& path) {
  std::unique_ptr<void, It8Free> it8(cmsIT8LoadFromFile(nullptr, path.c_str()));
  if (!it8) return std::nullopt;
  cmsHANDLE h = it8.get();
  std::vector<ca::CgatsTable> tables;
  for (cmsUInt32Number i = 0; i < cmsIT8TableCount(h); ++i) {
    if (cmsIT8SetTable(h, i) < 0) return std::nullopt;
    ca::CgatsTable t;
    if (const char* type = cmsIT8GetSheetType(h)) t.file_type = type;
    // lcms2 keeps the first line's trailing blanks ("CTI2   "); the type is the word.
    while (!t.file_type.empty() && (t.file_type.back() == ' ' || t.file_type.back() == '\t' || t.file_type.back() == '\r'))
      t.file_type.pop_back();
    char** names = nullptr;
    const auto n = cmsIT8EnumProperties(h, &names);
    for (cmsUInt32Number k = 0; names && k < n; ++k) {
      const char* v = cmsIT8GetProperty(h, names[k]);
      t.keywords.emplace_back(names[k], v ? v : "");
    }
    char** fields = nullptr;
    const int nf = cmsIT8EnumDataFormat(h, &fields);
    for (int f = 0; fields && f < nf; ++f) t.fields.emplace_back(fields[f] ? fields[f] : "");
    const int rows = static_cast<int>(cmsIT8GetPropertyDbl(h, "NUMBER_OF_SETS"));
    for (int r = 0; r < rows; ++r) {
      std::vector<std::string> row;
      for (int f = 0; f < nf; ++f) {
        const char* cell = cmsIT8GetDataRowCol(h, r, f);
        row.emplace_back(cell ? cell : "<missing>");
      }
      t.rows.push_back(std::move(row));
    }
    tables.push_back(std::move(t));
  }
  return tables;
}

std::vector<fs::path> shipped_cgats_files() {
  std::vector<fs::path> files;
  const std::vector<std::string> extensions{".ti1", ".ti2", ".ti3", ".cie", ".sp", ".cmf"};
  std::vector<fs::path> roots{"/usr/share/color/argyll/ref", "/usr/share/colord/cmf", "/usr/share/colord/illuminant"};
  if (auto data = colorlab::paths::shared_data_dir()) roots.push_back(*data);
  for (const auto& root : roots) {
    std::error_code ec;
    for (fs::recursive_directory_iterator it(root, ec), end; !ec && it != end; it.increment(ec)) {
      if (it->is_regular_file() &&
          std::find(extensions.begin(), extensions.end(), it->path().extension().string()) != extensions.end())
        files.push_back(it->path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

// lcms2 keeps numbers as it re-prints them ("106.60" becomes "106.6"): cells that are numbers in both
// readings compare as numbers, the rest as text.
bool same_cell(const std::string& a, const std::string& b) {
  if (a == b) return true;
  char* end_a = nullptr;
  char* end_b = nullptr;
  const double x = std::strtod(a.c_str(), &end_a), y = std::strtod(b.c_str(), &end_b);
  if (a.empty() || b.empty() || *end_a || *end_b) return false;
  return std::abs(x - y) <= 1e-9 * std::max(1.0, std::abs(x));
}

::testing::AssertionResult same_rows(const std::vector<std::vector<std::string>>& ours,
                                     const std::vector<std::vector<std::string>>& theirs) {
  if (ours.size() != theirs.size())
    return ::testing::AssertionFailure() << ours.size() << " rows against lcms2's " << theirs.size();
  for (std::size_t r = 0; r < ours.size(); ++r) {
    if (ours[r].size() != theirs[r].size()) return ::testing::AssertionFailure() << "row " << r + 1 << " width";
    for (std::size_t c = 0; c < ours[r].size(); ++c)
      if (!same_cell(ours[r][c], theirs[r][c]))
        return ::testing::AssertionFailure() << "row " << r + 1 << " cell " << c + 1 << ": '" << ours[r][c]
                                             << "' against lcms2's '" << theirs[r][c] << "'";
  }
  return ::testing::AssertionSuccess();
}

std::map<std::string, std::string> as_map(const ca::CgatsTable& t) {
  std::map<std::string, std::string> m(t.keywords.begin(), t.keywords.end());
  return m;
}

TEST(CgatsConformance, ReadsEveryShippedFileAsLcms2Does) {
  const auto files = shipped_cgats_files();
  if (files.size() < 20) GTEST_SKIP() << "ArgyllCMS's reference files are not installed (scripts/setup.sh installs argyll)";
  std::size_t compared = 0;
  std::vector<std::string> lcms2_refused;
  for (const auto& path : files) {
    SCOPED_TRACE(path.string());
    auto theirs = read_with_lcms2(path);
    if (!theirs) {
      lcms2_refused.push_back(path.filename().string());
      continue;
    }
    std::vector<ca::CgatsTable> ours;
    ASSERT_NO_THROW(ours = ca::read_cgats_all(path));
    ASSERT_EQ(ours.size(), theirs->size());
    for (std::size_t i = 0; i < ours.size(); ++i) {
      EXPECT_EQ(ours[i].file_type, (*theirs)[i].file_type);
      EXPECT_EQ(ours[i].fields, (*theirs)[i].fields);
      EXPECT_TRUE(same_rows(ours[i].rows, (*theirs)[i].rows));
      // Every keyword lcms2 saw, with its value; lcms2 lists them in its own order.
      const auto mine = as_map(ours[i]);
      for (const auto& [k, v] : (*theirs)[i].keywords) {
        auto it = mine.find(k);
        ASSERT_NE(it, mine.end()) << "keyword " << k;
        EXPECT_TRUE(same_cell(it->second, v)) << "keyword " << k << ": '" << it->second << "' against '" << v << "'";
      }
    }
    ++compared;
  }
  std::cout << "[cgats] " << compared << " files read alike by colorlab and lcms2; lcms2 refused "
            << lcms2_refused.size() << ":";
  for (const auto& f : lcms2_refused) std::cout << " " << f;
  std::cout << "\n";
  // Argyll ships two files whose NUMBER_OF_FIELDS disagrees with their format (ColorChecker.ti2,
  // FograStrip3.ti1); lcms2 refuses those, Argyll and colorlab read them.
  EXPECT_LE(lcms2_refused.size(), 4u);
  EXPECT_GE(compared, files.size() - 4);
}

}  // namespace
