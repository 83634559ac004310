#pragma once
// A campaign whose one measurement is the run's last step: one lab call (lab.wait, 5 s of wall time at time scale
// 100, in which a test sets a disk fault), then the measurement and the end, so that its step is committed only
// once the script has ended (commit_hold_test.cpp, disk_fault_test.cpp).
#include <filesystem>
#include <fstream>

namespace colorlab::testing {

// Writes it as `last-step` into the state directory's campaigns/.
inline void write_last_step_campaign(const std::filesystem::path& state_dir) {
  std::filesystem::create_directories(state_dir / "campaigns");
  std::ofstream(state_dir / "campaigns" / "last-step.lua") << R"lua(
return {
  description = "test: a wait, then one measurement as the run's last step",
  needs = {},
  parameters = {},
  run = function(p)
    lab.wait(500)
    lab.record("last", { quantity = "count", value = 1, unit = "1" })
  end,
}
)lua";
}

}  // namespace colorlab::testing
