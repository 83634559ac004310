#pragma once
// Environment for a child process that preloads a library (the fault shim, libfaketime).
#include <cstdlib>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace colorlab::testing {

// Environment variables set while a child starts (it inherits them), then restored: the test process
// itself must not run under what it preloads into the daemon.
class ScopedEnv {
 public:
  ScopedEnv(std::initializer_list<std::pair<const char*, std::string>> vars) {
    for (const auto& [name, value] : vars) {
      const char* old = std::getenv(name);
      saved_.emplace_back(name, old ? std::optional<std::string>(old) : std::nullopt);
      ::setenv(name, value.c_str(), 1);
    }
  }
  ~ScopedEnv() {
    for (const auto& [name, value] : saved_) {
      if (value) ::setenv(name, value->c_str(), 1);
      else ::unsetenv(name);
    }
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  std::vector<std::pair<const char*, std::optional<std::string>>> saved_;
};

// ASan (the asan preset) refuses to start when a preloaded library precedes its runtime.
inline std::string asan_options_for_preload() {
  const char* old = std::getenv("ASAN_OPTIONS");
  return std::string(old ? old : "") + ":verify_asan_link_order=0";
}

// TSan (the tsan preset) with a preloaded library and a report file (`log_path`, which scripts/tsan.sh sets) never
// got the daemon going: its log held only "ThreadSanitizer:DEADLYSIGNAL" (2026-11-29). The same under ASan the next
// day, where gdb showed why: the runtime, starting, makes the report's directory with mkdir, and the shim's mkdir,
// instrumented, faulted before the shadow memory existed. The shim is no longer instrumented (its CMakeLists.txt);
// until a TSan run confirms that was the whole cause, the daemon's TSan reports still go to its own stderr (the log
// beside the state directory), and halt_on_error still stops it, which fails the test.
inline std::string tsan_options_for_preload() {
  const char* old = std::getenv("TSAN_OPTIONS");
  std::string kept, option;
  std::string all = old ? old : "";
  for (char& c : all)
    if (c == ':' || c == ',') c = ' ';  // the sanitizers' own separators
  std::istringstream options(all);
  while (options >> option)
    if (option.rfind("log_path=", 0) != 0) kept += (kept.empty() ? "" : " ") + option;
  return kept;
}

}  // namespace colorlab::testing
