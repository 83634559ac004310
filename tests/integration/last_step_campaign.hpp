#pragma once
// A campaign whose one measurement is the run's last step: one lab call (lab.wait, 5 s of wall time at time scale
// 100, in which a test sets a disk fault), then the measurement and the end, so that its step is committed only
// once the script has ended (commit_hold_test.cpp, disk_fault_test.cpp).
#include <filesystem>

#include "resume_support.hpp"

namespace colorlab::testing {

// Installs it as `last-step` for the daemon of write_daemon_config(dir, …) (write_campaign).
inline void write_last_step_campaign(const std::filesystem::path& dir) {
  write_campaign(dir, "last-step.lua", R"lua(
return {
  description = "test: a wait, then one measurement as the run's last step",
  needs = {},
  parameters = {},
  run = function(p)
    lab.wait(500)
    lab.record("last", { quantity = "count", value = 1, unit = "1" })
  end,
}
)lua");
}

}  // namespace colorlab::testing
