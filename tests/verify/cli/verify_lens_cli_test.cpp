// `colorlab verify` placing the floor through the lab's lens calibration (issue 23, docs/verify.md "Where each spot
// is"): colorlabd's configuration holds [[lens]] tables, its embedded simulated lab runs a short floor-luminance, and
// the CLI says in `placement` — printed and stored — which lens it placed the floor through. The simulated floor
// camera has no distortion, so a calibration with k1 = k2 = 0 must place every spot exactly where the pinhole
// placement does (the same comparisons, bit for bit), while a distorted one moves the sampled regions; two
// calibrations of the photograph's size ask for a name, a name for another size or an unknown one is refused.
// (Where a distorted lens's spots must land is verify_floor_lens_test's, on the simulator's distorted floor view.)
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

#include <gtest/gtest.h>

#include "colorlab/client/runs.hpp"
#include "colorlab/sim/control_channel.hpp"
#include "colorlab/verify/rendering.hpp"
#include "ramp_rendering.hpp"
#include "colorlab/testing/simulator_capture.hpp"
#include "resume_support.hpp"

using namespace colorlab;
using namespace colorlab::testing;
using nlohmann::json;
using verify::cli_testing::ramp;
using verify::cli_testing::rendered;

namespace {

// The DSLR's full frame (the simulated lab's default) and three calibrations: two of its size, one of another.
const char* kLenses = R"(
[[lens]]
camera = "sim"
lens = "floor flat"
width_px = 3504
height_px = 2336
fx = 3900.0
fy = 3900.0
cx = 1751.5
cy = 1167.5
k1 = 0.0
k2 = 0.0
sigma = { fx = 4.0, fy = 4.0, cx = 2.0, cy = 2.0, k1 = 0.001, k2 = 0.01 }
source = "test"
date = "2026-11-29"

[[lens]]
camera = "sim"
lens = "floor barrel"
width_px = 3504
height_px = 2336
fx = 3900.0
fy = 3903.9
cx = 1755.0
cy = 1165.0
k1 = -0.10
k2 = 0.02
sigma = { fx = 4.0, fy = 4.0, cx = 2.0, cy = 2.0, k1 = 0.001, k2 = 0.01 }
source = "test"
date = "2026-11-29"

[[lens]]
camera = "sim"
lens = "half size"
width_px = 1752
height_px = 1168
fx = 1950.0
fy = 1950.0
cx = 875.5
cy = 583.5
sigma = { fx = 4.0, fy = 4.0, cx = 2.0, cy = 2.0, k1 = 0.001, k2 = 0.01 }
source = "test"
date = "2026-11-29"
)";

json control(const DaemonProcess& daemon, const json& command) {
  json endpoint = json::parse(std::ifstream(daemon.state_dir() / "colorlabd.endpoint"));
  return sim::send_control_command(endpoint.at("simulator_control").get<std::string>(), command);
}

TEST(VerifyLensCli, TheFloorIsPlacedThroughTheNamedCalibrationAndSaysSo) {
  TempDir dir;
  const auto config = write_daemon_config(dir.path(), 200, 11, kLenses);
  SimulatorCaptureFolder capture;
  DaemonProcess daemon(dir.path() / "state", config);
  capture.note(daemon);
  auto api = api_for(daemon);
  const json t = control(daemon, {{"cmd", "floor_truth"}, {"instrument", "dslr"}});
  json corners = json::array();
  for (const auto& c : t["floor_corners_px"]) {
    corners.push_back((c[0].get<double>() + 0.5) / t["width"].get<double>());
    corners.push_back((c[1].get<double>() + 0.5) / t["height"].get<double>());
  }
  const json params = {
      {"lamps", {"D65"}},
      {"dimmer_levels", {100}},
      {"settle_s", 0},
      {"rows", 2},
      {"cols", 3},
      {"frames", 2},
      {"corners", corners},
      {"calibration", {"r0c0", "r1c2"}},
  };
  const std::string floor = run_to_end(api, "floor-luminance", params)["id"].get<std::string>();
  const int w = t["width"].get<int>(), h = t["height"].get<int>();
  ASSERT_EQ(w, 3504);
  verify::write_openexr(ramp(w / 2, h / 2), dir.path() / "ramp.exr");  // any size: places scale with it

  const auto cli = [&](std::vector<std::string> extra) {
    std::vector<std::string> argv{bin_path("colorlab"), "--socket", daemon.unix_socket(), "verify",
                                  (dir.path() / "ramp.exr").string(), "--against", floor, "--json", "--scale", "1"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return run_command(argv, std::chrono::seconds(30));
  };

  // Two calibrations hold for 3504 × 2336: a name is needed.
  const auto both = cli({});
  EXPECT_EQ(both.exit_code, 1) << both.out;
  EXPECT_NE(both.err.find("--lens-calibration"), std::string::npos) << both.err;

  // The flat calibration: the pinhole's places exactly (k1 = k2 = 0), said to be the calibration.
  const auto flat = cli({"--lens-calibration", "sim / floor flat"});
  ASSERT_TRUE(flat.exit_code == 0 || flat.exit_code == 4) << flat.err;
  const json f = json::parse(flat.out);
  EXPECT_EQ(f["placement"]["light"]["model"], "lens calibration");
  EXPECT_NE(f["placement"]["light"]["lens"]["name"].get<std::string>().find("sim / floor flat"), std::string::npos);
  EXPECT_EQ(f["placement"]["light"]["lens"]["width_px"], 3504);
  const auto given = cli({"--lens", "3900,3900,1751.5,1167.5"});
  ASSERT_TRUE(given.exit_code == 0 || given.exit_code == 4) << given.err;
  const json g = json::parse(given.out);
  EXPECT_EQ(g["placement"]["light"]["lens"]["name"], "given with --lens");
  EXPECT_EQ(rendered(f), rendered(g));

  // The barrel calibration moves the regions: over the ramp the rendered values change.
  const auto barrel = cli({"--lens-calibration", "sim / floor barrel", "--store"});
  ASSERT_TRUE(barrel.exit_code == 0 || barrel.exit_code == 4) << barrel.err;
  const json b = json::parse(barrel.out);
  EXPECT_EQ(b["placement"]["light"]["lens"]["k1"], -0.10);
  ASSERT_EQ(rendered(b).size(), rendered(f).size());
  EXPECT_NE(rendered(b), rendered(f));
  // Stored: the run's params say how its light was placed.
  const json run = client::fetch_run(api, b.at("stored_run").get<std::string>());
  EXPECT_EQ(run["params"]["placement"], b["placement"]);

  // A calibration of another size, and an unknown one: refused, exit 1, naming the problem.
  const auto other = cli({"--lens-calibration", "sim / half size"});
  EXPECT_EQ(other.exit_code, 1);
  EXPECT_NE(other.err.find("1752"), std::string::npos) << other.err;
  const auto unknown = cli({"--lens-calibration", "no such lens"});
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_NE(unknown.err.find("no such lens"), std::string::npos) << unknown.err;
  const auto bad = cli({"--lens", "1,2,3"});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("4 or 6 numbers"), std::string::npos) << bad.err;
}

}  // namespace
