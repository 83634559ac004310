// The shipped unit file: systemd itself must accept it (systemd-analyze verify), and it must keep
// the properties colorlabd relies on — notify readiness, a watchdog, restart on failure — without
// PrivateDevices, which would hide the instruments' device nodes.
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include <gtest/gtest.h>

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
