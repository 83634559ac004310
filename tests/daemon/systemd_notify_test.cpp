// colorlabd under a service manager: READY=1 only after the database and sockets are up, then
// WATCHDOG=1 at half the WatchdogSec interval from the event loop. The test plays systemd by
// owning a NOTIFY_SOCKET datagram socket.
#include <stdlib.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <fstream>

#include <gtest/gtest.h>

#include "colorlab/testing/notify_socket.hpp"
#include "colorlab/testing/process.hpp"
#include "colorlab/testing/temp_dir.hpp"

using colorlab::testing::Process;
using colorlab::testing::TempDir;

TEST(Systemd, ReadyAfterStartupThenWatchdogPings) {
  TempDir dir;
  colorlab::testing::NotifySocket systemd(dir / "notify.sock");
  std::ofstream(dir / "colorlabd.toml") << "state_dir = \"state\"\nlisten = \"127.0.0.1:0\"\n";

  ::setenv("NOTIFY_SOCKET", systemd.path().c_str(), 1);
  ::setenv("WATCHDOG_USEC", "400000", 1);
  Process daemon({colorlab::testing::bin_path("colorlabd"), "--config", (dir / "colorlabd.toml").string()},
                 dir / "colorlabd.log");
  ::unsetenv("NOTIFY_SOCKET");
  ::unsetenv("WATCHDOG_USEC");

  std::string first = systemd.receive(std::chrono::seconds(10));
  EXPECT_NE(first.find("READY=1"), std::string::npos) << first;
  // By READY the database exists and the API answers.
  EXPECT_TRUE(std::filesystem::exists(dir / "state" / "colorlab.db"));
  EXPECT_TRUE(std::filesystem::exists(dir / "state" / "colorlabd.sock"));

  int pings = 0;
  for (int i = 0; i < 5 && pings < 2; ++i) {
    if (systemd.receive(std::chrono::seconds(2)).find("WATCHDOG=1") != std::string::npos) ++pings;
  }
  EXPECT_EQ(pings, 2);

  daemon.signal(SIGTERM);
  std::string last;
  for (int i = 0; i < 5; ++i) {
    last = systemd.receive(std::chrono::seconds(2));
    if (last.find("STOPPING=1") != std::string::npos || last.empty()) break;
  }
  EXPECT_NE(last.find("STOPPING=1"), std::string::npos);
  EXPECT_EQ(daemon.wait(std::chrono::seconds(10)), 0);
}
