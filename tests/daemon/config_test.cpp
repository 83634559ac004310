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

// The crash-loop guard's back-off and [notify] (docs/configuration.md): defaults, and every bad value
// refused with the file and line.
TEST(DaemonConfig, CrashLoopBackOffAndNotifyHaveDefaultsAndRefuseNonsense) {
  using colorlab::daemon::parse_config;
  auto d = parse_config("", "d.toml");
  EXPECT_EQ(d.campaigns.max_resume_attempts, 3);
  EXPECT_EQ(d.campaigns.crash_loop_backoff_s, 60);
  EXPECT_EQ(d.campaigns.crash_loop_backoff_max_s, 1800);
  EXPECT_EQ(d.campaigns.crash_loop_retries, 6);
  EXPECT_FALSE(d.notify.enabled());
  EXPECT_EQ(d.notify.events, (std::vector<std::string>{"suspended", "crash-loop", "failed"}));

  auto c = parse_config(R"([campaigns]
crash_loop_backoff_s = 0.5
crash_loop_backoff_max_s = 2
crash_loop_retries = 0
[notify]
command = ["/usr/local/bin/page-me", "--lab", "north"]
webhook = "https://hooks.example.invalid/T0/secret"
timeout_s = 3
events = ["crash-loop"]
)",
                        "c.toml");
  EXPECT_EQ(c.campaigns.crash_loop_backoff_s, 0.5);
  EXPECT_EQ(c.campaigns.crash_loop_backoff_max_s, 2);
  EXPECT_EQ(c.campaigns.crash_loop_retries, 0);
  EXPECT_EQ(c.notify.command, (std::vector<std::string>{"/usr/local/bin/page-me", "--lab", "north"}));
  EXPECT_EQ(c.notify.webhook, "https://hooks.example.invalid/T0/secret");
  EXPECT_EQ(c.notify.timeout_s, 3);
  EXPECT_EQ(c.notify.events, std::vector<std::string>{"crash-loop"});
  EXPECT_TRUE(c.notify.enabled());

  for (const char* bad : {"[campaigns]\ncrash_loop_backoff_s = 0\n", "[campaigns]\ncrash_loop_retries = -1\n",
                          "[campaigns]\ncrash_loop_backoff_s = 600\ncrash_loop_backoff_max_s = 60\n",
                          "[notify]\ncommand = \"page-me --now\"\n", "[notify]\ncommand = []\n",
                          "[notify]\nwebhook = \"ftp://x/\"\n", "[notify]\ntimeout_s = 0\n",
                          "[notify]\nevents = [\"finished\"]\n", "[notify]\nshell = true\n"}) {
    try {
      parse_config(bad, "bad.toml");
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("bad.toml:"), std::string::npos) << e.what();
      EXPECT_EQ(e.cls(), colorlab::ErrorClass::bad_parameter);
    }
  }
}

// colorlab-ship's [ship] section lives in the same file (docs/fleet.md): colorlabd accepts it, learns only that
// retention must keep unshipped blobs, and leaves its keys to colorlab-ship.
TEST(DaemonConfig, ShipSectionTurnsOnRetentionsGuardForUnshippedBlobs) {
  using colorlab::daemon::parse_config;
  EXPECT_FALSE(parse_config("", "d.toml").blobs.keep_unshipped);
  auto c = parse_config("[ship]\nbench_id = \"bench-1\"\npostgres = \"host=pg\"\n", "s.toml");
  EXPECT_TRUE(c.blobs.keep_unshipped);
  EXPECT_THROW(parse_config("ship = 3\n", "bad.toml"), Error);
}
