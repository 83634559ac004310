// The shipped unit file: systemd itself must accept it (systemd-analyze verify), and it must keep
// the properties colorlabd relies on — notify readiness, a watchdog, restart on failure — without
// PrivateDevices, which would hide the instruments' device nodes.
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include <gtest/gtest.h>

#include "colorlab/daemon/config.hpp"
#include "colorlab/daemon/crash_loop.hpp"
#include "colorlab/testing/process.hpp"
#include "colorlab/testing/temp_dir.hpp"

namespace {

std::string read_unit() {
  std::ifstream in(std::string(COLORLAB_SOURCE_DIR) + "/systemd/colorlabd.service");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

TEST(SystemdUnit, KeepsTheDirectivesColorlabdReliesOn) {
  std::string unit = read_unit();
  ASSERT_FALSE(unit.empty());
  for (const char* needed : {"Type=notify", "WatchdogSec=", "Restart=on-failure", "StateDirectory=colorlabd",
                             "ProtectSystem=strict", "NoNewPrivileges=yes", "DeviceAllow=char-ttyUSB rw"}) {
    EXPECT_NE(unit.find(needed), std::string::npos) << needed;
  }
  EXPECT_FALSE(std::regex_search(unit, std::regex("^PrivateDevices=", std::regex::multiline)))
      << "PrivateDevices would hide /dev/ttyUSB*, /dev/bus/usb and /dev/hidraw*";
}

double unit_seconds(const std::string& unit, const std::string& key) {
  std::smatch m;
  if (!std::regex_search(unit, m, std::regex("^" + key + "=([0-9]+)s?$", std::regex::multiline))) return -1;
  return std::stod(m[1]);
}

// systemd must keep restarting colorlabd while the crash-loop guard handles a step that kills it every
// time, with the default back-off, and the next queued run doing the same: otherwise the unit fails
// before the guard's first back-off has ended (issue 27: StartLimitBurst=5 per 300 s did).
TEST(SystemdUnit, StartLimitLetsTheCrashLoopGuardDoItsWork) {
  std::string unit = read_unit();
  const double interval = unit_seconds(unit, "StartLimitIntervalSec");
  const double burst = unit_seconds(unit, "StartLimitBurst");
  const double restart = unit_seconds(unit, "RestartSec");
  ASSERT_GT(interval, 0) << "StartLimitIntervalSec=N (seconds) expected";
  ASSERT_GT(burst, 0);
  ASSERT_GT(restart, 0);
  const colorlab::daemon::CampaignConfig defaults;
  const colorlab::daemon::CrashLoopPolicy policy{defaults.max_resume_attempts, defaults.crash_loop_backoff_s,
                                                 defaults.crash_loop_backoff_max_s, defaults.crash_loop_retries};
  const int needed = colorlab::daemon::max_starts_within(policy, interval, restart);
  EXPECT_LE(needed, burst) << "StartLimitBurst=" << burst << " per " << interval << " s stops systemd restarting "
                           << "colorlabd while the guard still needs " << needed << " starts";
  // The old limit would not have done: the guard's first back-off retry alone is the 6th start.
  EXPECT_GT(colorlab::daemon::max_starts_within(policy, 300, 5), 5);
}

TEST(SystemdUnit, SystemdAcceptsIt) {
  if (!std::filesystem::exists("/usr/bin/systemd-analyze")) GTEST_SKIP() << "systemd-analyze is not installed";
  colorlab::testing::TempDir dir;
  std::string unit = read_unit();
  unit = std::regex_replace(unit, std::regex("@CMAKE_INSTALL_FULL_SBINDIR@"), COLORLAB_BIN_DIR);
  unit = std::regex_replace(unit, std::regex("@CMAKE_INSTALL_FULL_DOCDIR@"), dir.path().string());
  std::ofstream(dir / "colorlabd.service") << unit;
  auto r = colorlab::testing::run_command({"/usr/bin/systemd-analyze", "verify", (dir / "colorlabd.service").string()});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(r.err.find("Unknown"), std::string::npos) << r.err;
}
