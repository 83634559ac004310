// colorlabd's embedded default: no configuration, the simulated lab started as a child process,
// and campaigns over its instruments — including the GigE Vision camera, so these tests hold the
// loopback camera lock.
#include <fstream>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "colorlab/testing/daemon.hpp"
#include "colorlab/testing/process.hpp"
#include "colorlab/testing/temp_dir.hpp"

using colorlab::testing::Process;
using nlohmann::json;

namespace {

class EmbeddedDaemon {
 public:
  EmbeddedDaemon()
      : daemon_({colorlab::testing::bin_path("colorlabd"), "--state", (dir_ / "state").string(), "--listen",
                 "127.0.0.1:0"},
                dir_ / "colorlabd.log") {
    // The Unix socket: campaigns are started, which loopback TCP allows only with a key.
    socket_ = colorlab::testing::wait_for_endpoint(dir_ / "state", daemon_.pid())["unix_socket"];
  }
  colorlab::testing::RunResult cli(std::vector<std::string> args) {
    std::vector<std::string> argv{colorlab::testing::bin_path("colorlab"), "--socket", socket_, "--json"};
    argv.insert(argv.end(), args.begin(), args.end());
    return colorlab::testing::run_command(argv, std::chrono::seconds(120));
  }
  Process& process() { return daemon_; }

 private:
  colorlab::testing::TempDir dir_;
  Process daemon_;
  std::string socket_;
};

}  // namespace

TEST(EmbeddedDefault, DaemonWithoutConfigStartsTheSimulatedLab) {
  EmbeddedDaemon daemon;
  auto status = daemon.cli({"status"});
  ASSERT_EQ(status.exit_code, 0) << status.err;
  EXPECT_TRUE(json::parse(status.out)["simulated_lab"]);
  auto run = daemon.cli({"run", "luminance-spot"});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  json j = json::parse(run.out);
  EXPECT_EQ(j["status"], "finished_ok");
  EXPECT_TRUE(j["simulated"]);
  EXPECT_TRUE(j["instruments"][0]["simulated"]);
  daemon.process().signal(SIGTERM);
  EXPECT_EQ(daemon.process().wait(std::chrono::seconds(10)), 0) << "colorlabd must stop cleanly on SIGTERM";
}

// Tuning (ctest label `tuning`): checks the simulator's tuning to the dissertation, not the analysis; the analysis is
// checked by AnalyticTruthAveraging.* (analysis_analytic_truth_test), the stored rows by
// BlobApi.FrameAverageKeepsItsFramesAndServesThemByteExact (recomputed from the kept average).
// §6.1.3 / Table 2 through the whole stack: GigE Vision over loopback, the camera driver, the
// analysis code, the store. Truth is the shape physics demands: the spread of an averaged uniform
// region falls with N, roughly as 1/√N at first, then levels off at the fixed-pattern floor.
TEST(EmbeddedDefault, FrameAverageReproducesTable2Shape) {
  EmbeddedDaemon daemon;
  json instruments = json::parse(daemon.cli({"instruments"}).out);
  bool have_camera = false;
  for (const auto& i : instruments["items"]) have_camera = have_camera || i["kind"] == "genicam";
  if (!have_camera) GTEST_SKIP() << "the simulated lab could not start its GigE Vision camera on 127.0.0.1";

  auto r = daemon.cli({"run", "frame-average", "--param", "frames=16"});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  json run = json::parse(r.out);
  ASSERT_EQ(run["status"], "finished_ok");
  const json& table = run["summary"]["script"]["stdev_by_frames_averaged"];
  for (const char* channel : {"R", "G", "B"}) {
    double s1 = table["1"][channel], s2 = table["2"][channel], s4 = table["4"][channel], s16 = table["16"][channel];
    EXPECT_GT(s1, s2) << channel;
    EXPECT_GT(s2, s4) << channel;
    EXPECT_GT(s4, s16) << channel;
    // Between 1/√N (pure temporal noise: 0.25 at N = 16) and no improvement at all.
    EXPECT_GT(s16 / s1, 0.25) << channel;
    EXPECT_LT(s16 / s1, 0.9) << channel;
  }
  // 5 subsets (1, 2, 4, 8, 16) × 3 channels, each stored once and flagged simulated.
  ASSERT_EQ(run["measurements"].size(), 15u);
  for (const auto& m : run["measurements"]) EXPECT_TRUE(m["simulated"]);
}
