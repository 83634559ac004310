// End to end through a daemon (issue 23, docs/verify.md "Blender through the daemon"): colorlabd's embedded
// simulated lab (the geometric cabinet: its light comes from the emitters' geometry, as a renderer's does) runs
// chart-read and characterize-camera; `colorlab scene` exports the measured scene from the daemon; Debian's Blender
// 3.4 renders the exported build_scene.py band by band from the exported camera (the located chart's pose, Cycles on
// the CPU, its own seed); `colorlab verify --against CHARACTERIZE_RUN --json` through the daemon gives the verdict and
// the exit status. Nothing of the scene is written by the test: it only stacks Blender's band images into one
// spectral OpenEXR (the JCGT layout verify reads) and, for the planted defect, scales them by linearity.
//
// Truth and bounds: the simulator photographed its true chart (the SG's spectra) lit by the emitters' form factors;
// Blender renders the Spectrolino's reading of it lit by Cycles' path tracing of the same emitters. A faithful
// rendering agrees on >= 95 % of the patches per kind (issue 23) — a k = 2 band's promise in expectation, so one
// rendering's count of false flags is a draw from Binomial(140, 0.05) (mean 7, σ 2.6): a test of "== 95 % or better"
// on one draw would fail half the time for a perfectly calibrated band. The bound here is that draw's 99.9 % quantile:
// at most 16 of 140 differ; the count itself is printed and stated beside the 95 % in docs/verify.md (merged tree,
// 2026-11-29: 134/140 and 135/140 agree, 95.7 % and 96.4 %). Cycles' own noise (16 samples per pixel in
// each band, a patch's region ~80 pixels at 480 × 320) is a stated source now (`rendering noise`, estimated from the
// rendering itself: docs/verify.md), so the band covers it; before it was, this rendering agreed on 132 and 129 of
// 140 (with the old tilt sign) and 129 and 128 (the sign fixed). What is still in no budget: the exported spectra are the Spectrolino's reading
// while the photograph saw the true chart (the chart-read run states no repeatability to budget it with; printed
// below as ΔE00 against the simulator's chart). A wrong renderer is still seen: the same bands lit by CIE A instead
// of D65 (exact by linearity: each band image is linear in that band's emission; the "wrong lamp spectrum"
// defect) must be flagged on >= 90 % of the patches in §7.3 (compare_defects_test's detection bound) with exit 4.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "colorlab/analysis/color_difference.hpp"
#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/analysis/standard_data.hpp"
#include "colorlab/sim/camera/camera_model.hpp"
#include "colorlab/sim/clock.hpp"
#include "colorlab/sim/scene.hpp"
#include "colorlab/testing/process.hpp"
#include "colorlab/testing/simulator_capture.hpp"
#include "colorlab/verify/rendering.hpp"
#include "resume_support.hpp"

namespace colorlab::verify {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;
using namespace colorlab::testing;

// The photograph is 1752 × 1168 (the DSLR at half size, as verify_colour_runs_test); the render keeps its aspect.
// The DSLR looks at the chart 30° from its normal at 600 mm (the camera 520 mm
// above the floor, under the lamps' 600 mm plane: a renderer must see the chart from inside the scene, which the
// simulator's bench poses — 1.2 m above the chart — are not).
constexpr int kPhotoWidth = 1752, kPhotoHeight = 1168;
constexpr double kTiltDeg = 30, kDistanceMm = 600;
constexpr int kWidth = 480, kHeight = 320, kSamples = 16;
constexpr std::uint64_t kSeed = 5;

std::string lab_toml() {
  return "[genicam]\nenabled = false\n[dslr]\nsize = [" + std::to_string(kPhotoWidth) + ", " + std::to_string(kPhotoHeight) +
         "]\npose = { tilt_deg = " + std::to_string(kTiltDeg) + ", distance_mm = " + std::to_string(kDistanceMm) +
         " }\n[scene]\nfloor_field = \"geometric\"\n";
}

// The lab's lens calibration: the simulator's own lens for that pose (what `colorlab scene --lens` takes; the lab
// stores none yet), so the exported camera stands where the photograph was taken.
std::string simulator_lens() {
  auto scene = std::make_shared<sim::Scene>(sim::SceneConfig{}, std::make_shared<sim::SimClock>(1.0));
  sim::camera::CameraConfig cc;
  cc.width = kPhotoWidth;
  cc.height = kPhotoHeight;
  sim::camera::ChartPose pose;
  pose.tilt_deg = kTiltDeg;
  pose.distance_mm = kDistanceMm;
  cc.pose = pose;
  const auto l = sim::camera::CameraModel(scene, cc).lens();
  std::ostringstream s;
  s.precision(10);
  s << l.fx << "," << l.fy << "," << l.cx << "," << l.cy;
  return s.str();
}

std::string read_file(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// An illuminant's relative power at `nm`, linear between its table's wavelengths.
double power_at(const analysis::SpectralSet& s, double nm) {
  const auto& w = s.wavelengths;
  for (std::size_t i = 0; i + 1 < w.size(); ++i)
    if (w[i] <= nm && nm <= w[i + 1]) {
      const double t = (nm - w[i]) / (w[i + 1] - w[i]);
      return (1 - t) * s.values(0, static_cast<Eigen::Index>(i)) + t * s.values(0, static_cast<Eigen::Index>(i + 1));
    }
  throw std::runtime_error("illuminant " + s.source + " has no value at " + std::to_string(nm) + " nm");
}

struct Tally {
  int compared = 0, differ = 0;
  std::vector<std::string> at;
};

std::map<std::string, Tally> tally(const json& result) {
  std::map<std::string, Tally> k;
  for (const auto& c : result["comparisons"]) {
    auto& t = k[c["kind"].get<std::string>()];
    ++t.compared;
    if (c["verdict"] == "differs") {
      ++t.differ;
      t.at.push_back(c["where"].get<std::string>());
    }
  }
  return k;
}

// The band images Blender wrote (renders.json lists them), in W·sr⁻¹·m⁻² per band, stacked into one spectral
// rendering per nm, each band multiplied by `factor(nm)`.
Rendering stack(const fs::path& renders, double step_nm, const std::function<double(double)>& factor) {
  const json listing = json::parse(read_file(renders / "renders.json"));
  std::vector<Rendering> bands;
  std::vector<double> nm;
  for (const auto& r : listing["renders"]) {
    bands.push_back(read_rendering(renders / r["file"].get<std::string>()));
    nm.push_back(r["band_nm"].get<double>());
    const double f = factor(nm.back()) / step_nm;
    for (auto& v : bands.back().pixels) v = static_cast<float>(v * f);
  }
  return assemble_spectral(bands, nm, "W.m^-2.sr^-1.nm^-1");
}

TEST(BlenderDaemon, TheDaemonsExportedSceneRenderedByBlenderIsVerifiedThroughTheDaemon) {
  if (!on_path("blender")) GTEST_SKIP() << "blender is not installed (scripts/setup.sh installs Debian's blender)";
  std::string blender_exe = shell_output("command -v blender");
  blender_exe.erase(blender_exe.find_last_not_of(" \n") + 1);  // run_command execs a path, not a name
  const auto t_start = std::chrono::steady_clock::now();
  auto seconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count(); };
  TempDir dir;
  auto config = write_daemon_config(dir.path(), 1000, kSeed);
  std::ofstream(dir.path() / "lab.toml") << lab_toml();
  SimulatorCaptureFolder capture;
  auto daemon = std::make_unique<DaemonProcess>(dir.path() / "state", config);
  capture.note(*daemon);
  const auto api = api_for(*daemon);
  auto cli = [&](std::vector<std::string> args, std::chrono::seconds timeout = std::chrono::seconds(120)) {
    std::vector<std::string> argv{bin_path("colorlab"), "--socket", daemon->unix_socket()};
    argv.insert(argv.end(), args.begin(), args.end());
    return run_command(argv, timeout);
  };

  std::string chart_read, characterize;
  try {
    chart_read = run_to_end(api, "chart-read", json::object())["id"].get<std::string>();
    const json run = run_to_end(api, "characterize-camera",
                                {{"reference_run", chart_read}, {"frames", 2}, {"formats", {"raw"}}, {"prior_exclude", {"Canon_20D"}}},
                                std::chrono::seconds(300));
    ASSERT_EQ(run["status"], "finished_ok") << run.dump().substr(0, 2000);
    characterize = run["id"].get<std::string>();
  } catch (const std::exception& e) {
    FAIL() << "the simulated lab's runs: " << e.what();
  }
  std::cout << "runs done at " << seconds() << " s\n";

  // The scene from the daemon's runs (and its cabinet): the camera from the chart located on the photograph.
  const fs::path scene_dir = dir.path() / "scene";
  const auto scene = cli({"scene", chart_read, characterize, "--lens", simulator_lens(), "-o", scene_dir.string()});
  ASSERT_EQ(scene.exit_code, 0) << scene.out << scene.err;
  const json exported = json::parse(read_file(scene_dir / "scene.json"));
  ASSERT_EQ(exported["camera"]["pose"]["source"], "located chart") << exported["camera"].dump(1);
  std::cout << "exported camera at " << exported["camera"]["position_m"].dump() << " m\n";
  const double step_nm = exported["bands"]["step_nm"].get<double>();
  {
    // What the renderer was given beside what the camera saw: the exported (Spectrolino-read) spectra against the
    // simulator's true chart, ΔE00 under D65 — the chart-read run states no repeatability to budget this with.
    const sim::Scene truth(sim::SceneConfig{}, std::make_shared<sim::SimClock>(1.0));
    std::vector<double> grid;
    for (std::size_t k = 0; k < 36; ++k) grid.push_back(380 + 10.0 * static_cast<double>(k));
    const analysis::ReflectanceIntegrator integ(analysis::load_illuminant("D65"), analysis::load_observer(analysis::Observer::cie1931_2deg), grid);
    std::vector<double> de;
    for (const auto& p : exported["chart"]["patches"]) {
      const auto idx = truth.chart().index_of(p["id"].get<std::string>());
      const auto read = p["reflectance"]["values"].get<std::vector<double>>();
      if (!idx || read.size() != grid.size()) continue;
      const std::vector<double> real = truth.chart().patches[static_cast<std::size_t>(*idx)].reflectance.resampled(380, 10, grid.size()).values;
      const auto lab = [&](const std::vector<double>& r) {
        return analysis::xyz_to_lab(integ.xyz(Eigen::Map<const Eigen::RowVectorXd>(r.data(), static_cast<Eigen::Index>(r.size()))), integ.white());
      };
      de.push_back(analysis::delta_e2000(lab(read), lab(real)));
    }
    std::sort(de.begin(), de.end());
    if (!de.empty())
      std::cout << "exported spectra against the simulator's true chart (" << de.size() << " patches): ΔE00 median " << de[de.size() / 2]
                << ", max " << de.back() << "\n";
  }

  // Every band once (Blender's own seed); bounded: a hung Blender is killed and its log shown.
  const fs::path renders = dir.path() / "renders";
  const auto blender = run_command({blender_exe, "-b", "--factory-startup", "-noaudio", "-P", (scene_dir / "build_scene.py").string(), "--",
                                    "--mode", "bands", "--view", "camera", "--size", std::to_string(kWidth) + "x" + std::to_string(kHeight),
                                    "--samples", std::to_string(kSamples), "--seed", "7", "--threads", "2", "--out", renders.string()},
                                   std::chrono::seconds(600));
  ASSERT_EQ(blender.exit_code, 0) << "blender failed or was killed after 600 s:\n"
                                  << blender.out.substr(blender.out.size() > 4000 ? blender.out.size() - 4000 : 0) << blender.err;
  std::cout << "blender done at " << seconds() << " s\n";

  const fs::path faithful = dir.path() / "blender_d65.exr", wrong_lamp = dir.path() / "blender_as_if_A.exr";
  write_openexr(stack(renders, step_nm, [](double) { return 1.0; }), faithful);
  const auto d65 = analysis::load_illuminant("D65"), a = analysis::load_illuminant("A");
  write_openexr(stack(renders, step_nm, [&](double nm) { return power_at(a, nm) / power_at(d65, nm); }), wrong_lamp);

  auto verify = [&](const fs::path& file) {
    const auto r = cli({"verify", file.string(), "--against", characterize, "--json"});
    EXPECT_TRUE(r.exit_code == 0 || r.exit_code == 4) << "no verdict (exit " << r.exit_code << "): " << r.err;
    json j = r.out.empty() ? json::object() : json::parse(r.out);
    EXPECT_EQ(j.value("exit_status", -1), r.exit_code);
    return std::pair{r.exit_code, j};
  };
  {
    SCOPED_TRACE("Blender's rendering of the exported scene agrees with the measurement as a calibrated k = 2 band allows");
    const auto [rc, result] = verify(faithful);
    ASSERT_TRUE(result.contains("comparisons")) << result.dump().substr(0, 2000);
    const auto k = tally(result);
    for (const char* kind : {"colour_7_3", "colour_7_4"}) {
      ASSERT_TRUE(k.count(kind)) << kind << " not compared: " << result.dump().substr(0, 2000);
      const auto& t = k.at(kind);
      EXPECT_EQ(t.compared, 140) << kind;
      std::cout << kind << ": " << t.compared - t.differ << "/" << t.compared << " agree; differ at";
      for (const auto& w : t.at) std::cout << " " << w;
      std::cout << "\n";
      // Binomial(140, 0.05)'s 99.9 % quantile (see the top): more would say the band is too narrow.
      constexpr int kMostFalseFlags = 16;
      EXPECT_LE(t.differ, kMostFalseFlags) << kind << "\n"
                                           << result["summary"][kind].dump(1);
      std::cout << kind << ": " << (t.differ <= 7 ? "at or above" : "below") << " the issue's 95 % in this rendering\n";
    }
    // What the rendering's own noise (Cycles at 16 samples) adds to each band, beside the whole band: medians.
    for (const char* kind : {"colour_7_3", "colour_7_4"}) {
      std::vector<double> noise, band;
      for (const auto& c : result["comparisons"])
        if (c["kind"] == kind) {
          noise.push_back(c["budget"].value("rendering noise", 0.0));
          band.push_back(c["expanded"].get<double>() / 2);
        }
      std::sort(noise.begin(), noise.end());
      std::sort(band.begin(), band.end());
      if (!noise.empty())
        std::cout << kind << ": rendering noise along the difference, median " << noise[noise.size() / 2] << " (max "
                  << noise.back() << "), against a whole band's u median " << band[band.size() / 2] << "\n";
    }
    // The exit status is the verdict: 0 exactly when nothing differs.
    const bool any = k.at("colour_7_3").differ + k.at("colour_7_4").differ > 0;
    EXPECT_EQ(rc, any ? 4 : 0);
    EXPECT_EQ(result["summary"]["verdict"], any ? "differs" : "agrees");
    std::cout << "faithful: verdict " << result["summary"]["verdict"] << ", exit " << rc << "; colour " << result["colour"].dump() << "\n";
  }
  {
    SCOPED_TRACE("the same bands lit by CIE A instead of D65: flagged nearly everywhere, exit 4");
    const auto [rc, result] = verify(wrong_lamp);
    ASSERT_TRUE(result.contains("comparisons")) << result.dump().substr(0, 2000);
    const auto k = tally(result);  // by value: a reference into tally()'s temporary would dangle
    ASSERT_TRUE(k.count("colour_7_3")) << result.dump().substr(0, 2000);
    const auto& t = k.at("colour_7_3");
    std::cout << "under A: " << t.differ << "/" << t.compared << " differ in colour_7_3\n";
    EXPECT_GE(static_cast<double>(t.differ) / t.compared, 0.90);
    EXPECT_EQ(rc, 4);
    EXPECT_EQ(result["summary"]["verdict"], "differs");
  }
  std::cout << "wall " << seconds() << " s\n";
}

}  // namespace
}  // namespace colorlab::verify
