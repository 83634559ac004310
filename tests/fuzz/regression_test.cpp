// Every fuzz target's seed corpus and every input that once crashed it (tests/fuzz/regressions/<name>/)
// replayed through the same harness in the normal build, so a fixed crash stays fixed where clang's
// libFuzzer is missing too. A harness aborts on anything but a typed colorlab::Error, so a regression
// shows as this test dying with the harness's message after the "replaying" line naming the file.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "fuzz_support.hpp"

namespace {

namespace fs = std::filesystem;

std::vector<std::string> declared_targets() {
  std::vector<std::string> names;
  std::stringstream list(COLORLAB_FUZZ_TARGET_NAMES);
  for (std::string name; std::getline(list, name, ';');) names.push_back(name);
  return names;
}

std::vector<fs::path> files_of(const std::string& target) {
  std::vector<fs::path> files;
  for (const char* kind : {"corpus", "regressions"}) {
    const fs::path dir = fs::path(COLORLAB_SOURCE_DIR) / "tests" / "fuzz" / kind / target;
    if (!fs::is_directory(dir)) continue;
    for (const auto& entry : fs::directory_iterator(dir)) {
      if (entry.is_regular_file()) files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

class FuzzReplay : public testing::TestWithParam<std::string> {};

TEST_P(FuzzReplay, CorpusAndRegressionsEndInTypedErrorsOrSuccess) {
  const auto& targets = colorlab::fuzz::targets();
  auto it = targets.find(GetParam());
  ASSERT_NE(it, targets.end()) << GetParam() << "_fuzz.cpp is not linked into this test";
  const auto files = files_of(GetParam());
  EXPECT_FALSE(files.empty()) << "no seed corpus for " << GetParam();
  for (const auto& file : files) {
    std::cerr << "replaying " << file.string() << std::endl;
    std::ifstream in(file, std::ios::binary);
    const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    it->second(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  }
}

INSTANTIATE_TEST_SUITE_P(Targets, FuzzReplay, testing::ValuesIn(declared_targets()),
                         [](const testing::TestParamInfo<std::string>& info) { return info.param; });

}  // namespace
