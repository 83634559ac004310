#pragma once
// Shared by the third-party client tests: a missing client fails in CI and skips elsewhere, bounded
// polling of the simulator's truth, and the simulated DMX widget's truth as plain numbers.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <functional>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "colorlab/testing/process.hpp"

namespace colorlab::test {

// CI runs on a machine scripts/setup.sh provisioned, so a client missing there means a test silently
// stopped testing (scripts/test.sh's skip rule); on a developer's machine it is a skip with the reason.
inline bool in_ci() {
  const char* ci = std::getenv("CI");
  return ci && *ci;
}

#define COLORLAB_REQUIRE_CLIENT(condition, reason)                                                   \
  do {                                                                                               \
    if (!(condition)) {                                                                              \
      if (::colorlab::test::in_ci()) FAIL() << (reason) << " — scripts/setup.sh installs it for CI"; \
      GTEST_SKIP() << (reason);                                                                      \
    }                                                                                                \
  } while (0)

// A tool's absolute path (colorlab::testing::Process and run_command exec without a PATH search), or "".
inline std::string tool_path(const std::string& tool) {
  std::string p = colorlab::testing::shell_output("command -v " + tool);
  while (!p.empty() && (p.back() == '\n' || p.back() == ' ')) p.pop_back();
  return p;
}

// Polls `probe` until it returns true or `limit` passes; the last observation goes into the failure.
inline bool wait_for(const std::function<bool(std::string& seen)>& probe, std::chrono::milliseconds limit,
                     std::string& seen) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  for (;;) {
    if (probe(seen)) return true;
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

// The first `n` DMX slots the simulated widget last received (its truth; 0 where the packet was shorter).
inline std::vector<int> truth_slots(const nlohmann::json& truth, std::size_t n) {
  std::vector<int> out(n, 0);
  const auto& slots = truth["dmx"]["slots"];
  for (std::size_t i = 0; i < n && i < slots.size(); ++i) out[i] = slots[i].get<int>();
  return out;
}

}  // namespace colorlab::test
