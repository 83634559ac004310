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

namespace {

bool on_path(const char* tool) {
  std::string cmd = std::string("command -v ") + tool + " >/dev/null 2>&1";
  return std::system(cmd.c_str()) == 0;
}

std::string run(const std::string& cmd) {
  std::string out;
  std::unique_ptr<FILE, int (*)(FILE*)> p(::popen(cmd.c_str(), "r"), ::pclose);
  if (!p) return out;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, p.get())) out += buf;
  return out;
}

}  // namespace

TEST(SimConformance, SpotreadReadsTheSimulatedSpectrolino) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root for unshare -m and a private /dev (instrument-protocols §5.3)";
  if (!on_path("spotread")) GTEST_SKIP() << "ArgyllCMS spotread is not installed (Debian package argyll)";
  if (!on_path("unshare") || !on_path("python3")) GTEST_SKIP() << "needs unshare and python3";

  colorlab::test::SimProcess sim(R"(
time_scale = 10.0
[spectrolino]
table = false
[ls110]
enabled = false
[dmx]
enabled = false
)");
  std::string driver = std::string(COLORLAB_SOURCE_DIR) + "/tests/sim/conformance/argyll_driver.py";
  std::string log = (sim.dir() / "spotread.log").string();
  std::string cmd = "timeout 150 python3 " + driver + " spotread --port " + sim.port("spectrolino") + " --control " +
                    sim.announcement()["control"].get<std::string>() + " --patch D4 --workdir " + sim.dir().string() +
                    " --log " + log;
  std::string out = run(cmd);
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
}
