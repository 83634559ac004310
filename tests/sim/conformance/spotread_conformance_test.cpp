// Independent conformance: ArgyllCMS spotread (Debian's argyll, a client nobody here wrote) identifies
// the simulated Spectrolino, calibrates on its white tile and reads a chart patch; the XYZ it prints
// must equal the scene's truth (D50, 2 deg, from the patch's true reflectance) within the simulated
// noise. Needs root, unshare and spotread (instrument-protocols.md §5.3); skips with the reason otherwise.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "../serial/sim_process.hpp"
#include "colorlab/analysis/colorimetry.hpp"

#include "colorlab/testing/process.hpp"

using colorlab::testing::on_path;
using colorlab::testing::shell_output;

// power_on_baud 19200 also exercises Argyll's speed scan and the 4D 27 switch back to 9600 (§5.4 d).
class SimSpotread : public ::testing::TestWithParam<int> {};

TEST_P(SimSpotread, ReadsTheSimulatedSpectrolino) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root for unshare -m and a private /dev (instrument-protocols §5.3)";
  if (!on_path("spotread")) GTEST_SKIP() << "ArgyllCMS spotread is not installed (Debian package argyll)";
  if (!on_path("unshare") || !on_path("python3")) GTEST_SKIP() << "needs unshare and python3";

  colorlab::test::SimProcess sim(R"(
time_scale = 10.0
[spectrolino]
table = false
power_on_baud = )" + std::to_string(GetParam()) +
                                 R"(
[ls110]
enabled = false
[dmx]
enabled = false
[genicam]
enabled = false
)");
  std::string driver = std::string(COLORLAB_SOURCE_DIR) + "/tests/sim/conformance/argyll_driver.py";
  std::string log = (sim.dir() / "spotread.log").string();
  std::string cmd = "timeout 150 python3 " + driver + " spotread --port " + sim.port("spectrolino") + " --control " +
                    sim.announcement()["control"].get<std::string>() + " --patch D4 --workdir " + sim.dir().string() +
                    " --log " + log;
  std::string out = shell_output(cmd);
  auto result = nlohmann::json::parse(out, nullptr, false);
  ASSERT_FALSE(result.is_discarded()) << "driver printed: " << out;
  ASSERT_TRUE(result.value("ok", false)) << result.dump() << "\n(see " << log << ")";
  EXPECT_EQ(result["device"], "Spectrolino");
  EXPECT_EQ(result["serial"], "12345");
  EXPECT_EQ(result["exit"], 0);

  namespace an = colorlab::analysis;
  an::ReflectanceIntegrator integ(an::load_illuminant("D50"), an::load_observer(an::Observer::cie1931_2deg),
                                  an::uniform_grid(380, 730, 10));
  auto truth_spectrum = result["true_spectrum"].get<std::vector<double>>();
  ASSERT_EQ(truth_spectrum.size(), 36u);
  Eigen::RowVectorXd r = Eigen::Map<Eigen::RowVectorXd>(truth_spectrum.data(), 36);
  auto truth = integ.xyz(r);
  auto got = result["xyz"].get<std::vector<double>>();
  // Simulated repeatability is ~0.1 % gain + 0.05..0.15 % per band: well under 1 % of Y.
  EXPECT_NEAR(got[0], truth.X, 0.6);
  EXPECT_NEAR(got[1], truth.Y, 0.6);
  EXPECT_NEAR(got[2], truth.Z, 0.6);
  EXPECT_GT(std::abs(got[1] - 100.0), 5.0) << "a patch, not the white tile, was read";
  EXPECT_EQ(sim.control({{"cmd", "truth"}})["spectrolino"]["baud"], 9600);
}

INSTANTIATE_TEST_SUITE_P(PowerOnSpeed, SimSpotread, ::testing::Values(9600, 19200));

// chartread drives the SpectroScan T itself: white calibration on the tile, then D0 07 MoveAndMeasure
// along a strip whose ends the "operator" (this test, through the control socket) located with the
// sight. The strip is laid over one row of the ColorChecker SG, so every reading must equal the true
// reflectance of the SG patch under it.
TEST(SimConformance, ChartreadReadsAStripFromTheSpectroScan) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root for unshare -m and a private /dev (instrument-protocols §5.3)";
  if (!on_path("chartread") || !on_path("targen") || !on_path("printtarg")) {
    GTEST_SKIP() << "ArgyllCMS chartread/targen/printtarg are not installed (Debian package argyll)";
  }
  if (!on_path("unshare") || !on_path("python3")) GTEST_SKIP() << "needs unshare and python3";

  colorlab::test::SimProcess sim(R"(
time_scale = 20.0
[ls110]
enabled = false
[dmx]
enabled = false
[genicam]
enabled = false
)");
  constexpr int kPatches = 12;  // SG columns B..M of row 3
  auto head_at = [&](const std::string& patch) {
    auto r = sim.control({{"cmd", "place"}, {"target", "patch"}, {"patch", patch}});
    EXPECT_TRUE(r["ok"].get<bool>()) << r.dump();
    return r["spectrolino"];
  };
  auto first = head_at("B3")["head_mm"];
  auto last = head_at("M3")["head_mm"];
  sim.control({{"cmd", "place"}, {"x_mm", 0.0}, {"y_mm", 0.0}});
  auto xy = [](const nlohmann::json& p) {
    return std::to_string(p[0].get<double>()) + "," + std::to_string(p[1].get<double>());
  };
  std::string driver = std::string(COLORLAB_SOURCE_DIR) + "/tests/sim/conformance/argyll_driver.py";
  std::string log = (sim.dir() / "chartread.log").string();
  std::string cmd = "timeout 170 python3 " + driver + " chartread --port " + sim.port("spectrolino") + " --control " +
                    sim.announcement()["control"].get<std::string>() + " --workdir " + sim.dir().string() +
                    " --patches " + std::to_string(kPatches) + " --first " + xy(first) + " --last " + xy(last) +
                    " --log " + log;
  std::string out = shell_output(cmd);
  auto result = nlohmann::json::parse(out, nullptr, false);
  ASSERT_FALSE(result.is_discarded()) << "driver printed: " << out;
  ASSERT_TRUE(result.value("ok", false)) << result.dump() << "\n(see " << log << ")";
  EXPECT_EQ(result["table"], "SpectroScanT");
  EXPECT_EQ(result["exit"], 0);
  const auto& patches = result["patches"];
  ASSERT_EQ(patches.size(), static_cast<std::size_t>(kPatches));
  const std::string columns = "ABCDEFGHIJKLMN";
  for (int k = 1; k <= kPatches; ++k) {
    std::string loc = "A" + std::to_string(k);
    ASSERT_TRUE(patches.contains(loc)) << loc;
    std::string sg = std::string(1, columns[static_cast<std::size_t>(k)]) + "3";
    auto truth = head_at(sg)["surface_spectrum"].get<std::vector<double>>();
    auto got = patches[loc].get<std::vector<double>>();
    ASSERT_EQ(got.size(), 36u);
    for (std::size_t i = 0; i < 36; ++i) EXPECT_NEAR(got[i], truth[i], 0.01) << loc << " = SG " << sg << " band " << i;
  }
}
