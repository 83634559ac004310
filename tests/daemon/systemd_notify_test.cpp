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

#include "colorlab/testing/process.hpp"
#include "colorlab/testing/temp_dir.hpp"

using colorlab::testing::Process;
using colorlab::testing::TempDir;

namespace {

std::string receive(int fd, std::chrono::milliseconds timeout) {
  timeval tv{static_cast<time_t>(timeout.count() / 1000), static_cast<suseconds_t>((timeout.count() % 1000) * 1000)};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  char buf[1024];
  ssize_t n = ::recv(fd, buf, sizeof buf, 0);
  return n > 0 ? std::string(buf, static_cast<size_t>(n)) : std::string();
}

}  // namespace

TEST(Systemd, ReadyAfterStartupThenWatchdogPings) {
  TempDir dir;
  std::string sock_path = (dir / "notify.sock").string();
  int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, sock_path.c_str(), sizeof addr.sun_path - 1);
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  std::ofstream(dir / "colorlabd.toml") << "state_dir = \"state\"\nlisten = \"127.0.0.1:0\"\n";

  ::setenv("NOTIFY_SOCKET", sock_path.c_str(), 1);
  ::setenv("WATCHDOG_USEC", "400000", 1);
  Process daemon({colorlab::testing::bin_path("colorlabd"), "--config", (dir / "colorlabd.toml").string()},
                 dir / "colorlabd.log");
  ::unsetenv("NOTIFY_SOCKET");
  ::unsetenv("WATCHDOG_USEC");

  std::string first = receive(fd, std::chrono::seconds(10));
  EXPECT_NE(first.find("READY=1"), std::string::npos) << first;
  // By READY the database exists and the API answers.
  EXPECT_TRUE(std::filesystem::exists(dir / "state" / "colorlab.db"));
  EXPECT_TRUE(std::filesystem::exists(dir / "state" / "colorlabd.sock"));

  int pings = 0;
  for (int i = 0; i < 5 && pings < 2; ++i) {
    if (receive(fd, std::chrono::seconds(2)).find("WATCHDOG=1") != std::string::npos) ++pings;
  }
  EXPECT_EQ(pings, 2);

  daemon.signal(SIGTERM);
  std::string last;
  for (int i = 0; i < 5; ++i) {
    last = receive(fd, std::chrono::seconds(2));
    if (last.find("STOPPING=1") != std::string::npos || last.empty()) break;
  }
  EXPECT_NE(last.find("STOPPING=1"), std::string::npos);
  EXPECT_EQ(daemon.wait(std::chrono::seconds(10)), 0);
  ::close(fd);
}
