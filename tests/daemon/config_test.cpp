#include <fstream>

#include <gtest/gtest.h>

#include "colorlab/core/error.hpp"
#include "colorlab/daemon/config.hpp"
#include "colorlab/testing/temp_dir.hpp"

using colorlab::Error;
using colorlab::daemon::apply_listen;
using colorlab::daemon::DaemonConfig;
using colorlab::daemon::load_config;

TEST(DaemonConfig, ListenParsesHostAndPort) {
  DaemonConfig c;
  apply_listen(c, "0.0.0.0:9000");
  EXPECT_EQ(c.listen_host, "0.0.0.0");
  EXPECT_EQ(c.listen_port, 9000);
  apply_listen(c, "[::1]:0");
  EXPECT_EQ(c.listen_host, "::1");
  EXPECT_EQ(c.listen_port, 0);
  for (const char* bad : {"localhost", ":80", "1.2.3.4:", "1.2.3.4:70000", "1.2.3.4:8x"}) {
    EXPECT_THROW(apply_listen(c, bad), Error) << bad;
  }
}

TEST(DaemonConfig, EmbeddedDefaultStartsTheSimulator) {
  auto c = colorlab::daemon::embedded_default_config();
  EXPECT_TRUE(c.simulator.enabled);
  EXPECT_EQ(c.database_path(), std::filesystem::path("./colorlab-state/colorlab.db"));
  EXPECT_EQ(c.socket_path(), std::filesystem::path("./colorlab-state/colorlabd.sock"));
}

TEST(DaemonConfig, LoadsInstrumentsAndResolvesRelativePaths) {
  colorlab::testing::TempDir dir;
  std::ofstream(dir / "colorlabd.toml") << R"(
state_dir = "state"
listen = "127.0.0.1:9100"

[[instrument]]
id = "meter"
kind = "ls110"
port = "/dev/ttyUSB0"
options = { reply_timeout_ms = 800 }
)";
  auto c = load_config(dir / "colorlabd.toml");
  EXPECT_EQ(c.state_dir, dir.path() / "state");
  EXPECT_EQ(c.listen_port, 9100);
  EXPECT_FALSE(c.simulator.enabled);
  ASSERT_EQ(c.instruments.size(), 1u);
  EXPECT_EQ(c.instruments[0].kind, "ls110");
  EXPECT_EQ(c.instruments[0].options["reply_timeout_ms"], 800);
}

TEST(DaemonConfig, ErrorsNameFileAndLine) {
  colorlab::testing::TempDir dir;
  std::ofstream(dir / "bad.toml") << "listen = \"127.0.0.1:1\"\n\nbogus = 3\n";
  try {
    load_config(dir / "bad.toml");
    FAIL();
  } catch (const Error& e) {
    std::string what = e.what();
    EXPECT_NE(what.find("bad.toml:3"), std::string::npos) << what;
    EXPECT_NE(what.find("bogus"), std::string::npos) << what;
  }
  std::ofstream(dir / "syntax.toml") << "listen = \n";
  EXPECT_THROW(load_config(dir / "syntax.toml"), Error);
  std::ofstream(dir / "noport.toml") << "[[instrument]]\nid = \"x\"\nkind = \"ls110\"\n";
  EXPECT_THROW(load_config(dir / "noport.toml"), Error);
}

TEST(DaemonConfig, QueueAutostartIsOffUnlessSaidAndOtherQueueKeysAreRefused) {
  colorlab::testing::TempDir dir;
  std::ofstream(dir / "none.toml") << "listen = \"127.0.0.1:1\"\n";
  EXPECT_FALSE(load_config(dir / "none.toml").queue.autostart);
  std::ofstream(dir / "on.toml") << "[queue]\nautostart = true\n";
  EXPECT_TRUE(load_config(dir / "on.toml").queue.autostart);
  std::ofstream(dir / "typo.toml") << "[queue]\nautostart = \"yes\"\n";
  EXPECT_THROW(load_config(dir / "typo.toml"), Error);
  std::ofstream(dir / "unknown.toml") << "[queue]\n\nretries = 2\n";
  try {
    load_config(dir / "unknown.toml");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("unknown.toml:3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("queue.retries"), std::string::npos) << e.what();
  }
}
