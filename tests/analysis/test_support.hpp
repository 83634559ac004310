#pragma once
// Shared helpers for the analysis tests: locating optional reference data and tools, temp dirs, running tools.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <unistd.h>

#include "colorlab/core/data_paths.hpp"

namespace colorlab::analysis::testing {

// Skips the calling test (GTEST_SKIP needs to be in the test body, so this returns a path or empty).
inline std::optional<std::filesystem::path> shared(const std::string& name) { return paths::shared_data_file(name); }

inline bool have_tool(const std::string& tool) {
  return std::system(("command -v " + tool + " >/dev/null 2>&1").c_str()) == 0;
}

// Scratch directories are removed when the test program exits (kept with COLORLAB_KEEP_TEST_FILES=1 for debugging).
struct TempDirs {
  std::vector<std::filesystem::path> dirs;
  ~TempDirs() {
    if (std::getenv("COLORLAB_KEEP_TEST_FILES")) return;
    std::error_code ec;
    for (const auto& d : dirs) std::filesystem::remove_all(d, ec);
  }
};

inline std::filesystem::path temp_dir(const std::string& tag) {
  static TempDirs registry;
  auto base = std::filesystem::temp_directory_path() /
              ("colorlab-analysis-" + tag + "-" + std::to_string(::getpid()) + "-" + std::to_string(registry.dirs.size()));
  std::filesystem::create_directories(base);
  registry.dirs.push_back(base);
  return base;
}

// Runs a shell command quietly; returns its exit status.
inline int run(const std::string& cmd) { return std::system((cmd + " >/dev/null 2>&1").c_str()); }

}  // namespace colorlab::analysis::testing

#define COLORLAB_REQUIRE_SHARED(var, name)                                                          \
  auto var##_opt = ::colorlab::analysis::testing::shared(name);                                     \
  if (!var##_opt) GTEST_SKIP() << "shared data file " << (name) << " not present (../shared/data)"; \
  const std::filesystem::path var = *var##_opt

#define COLORLAB_REQUIRE_TOOL(tool) \
  if (!::colorlab::analysis::testing::have_tool(tool)) GTEST_SKIP() << (tool) << " not installed (Debian package argyll)"
