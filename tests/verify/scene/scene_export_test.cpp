// scene.json from a simulated geometric cabinet's runs: its parts, every patch spectrum exactly as the
// chart-read stored it, patch placement against the simulator's own chart layout (separate code), lamp spectra
// against the CIE tables of the shared data set (not colord's copy the export reads), the lamp level fitted to
// the LS-110 readings against the simulator's emitter, the refusals, and the CLI writing both files.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <unistd.h>

#include "colorlab/core/data_paths.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/verify/scene_export.hpp"
#include "simulated_runs.hpp"

namespace colorlab::verify {
namespace {

using nlohmann::json;
using testing::chart_read_run;
using testing::cabinet_grid_run;

struct Fixture {
  std::shared_ptr<sim::SimClock> clock = std::make_shared<sim::SimClock>(1.0);
  std::unique_ptr<sim::Scene> scene;
  json chart, grid;
  Fixture() {
    sim::SceneConfig c;
    c.geometric_cabinet = default_cabinet();
    scene = std::make_unique<sim::Scene>(c, clock);
    chart = chart_read_run(*scene, 11);
    grid = cabinet_grid_run(*scene, {sim::Lamp::d65, sim::Lamp::tl84}, {100.0, 50.0}, 12);
  }
};

const Fixture& fixture() {
  static const Fixture f;
  return f;
}

std::string read_file(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

TEST(SceneExport, EveryPatchSpectrumIsTheChartReadsStoredOneAtItsPlaceOnTheFloor) {
  const auto& f = fixture();
  const json s = export_scene(default_cabinet(), {f.chart, f.grid});
  EXPECT_EQ(s["schema"], "colorlab-scene/1");
  const auto& patches = s["chart"]["patches"];
  ASSERT_EQ(patches.size(), 140u);
  EXPECT_EQ(s["chart"]["source_run"], f.chart["run"]["id"]);
  for (std::size_t i = 0; i < patches.size(); ++i) {
    const json& stored = f.chart["measurements"][i]["data"];
    const json& p = patches[i];
    EXPECT_EQ(p["id"], stored["id"]);
    EXPECT_EQ(p["reflectance"]["values"], stored["values"]) << p["id"];  // bit for bit
    EXPECT_EQ(p["reflectance"]["first_nm"], 380.0);
    EXPECT_EQ(p["reflectance"]["step_nm"], 10.0);
    // The simulator places its chart with its own layout code (sim/scene/src/chart.cpp).
    const auto [x, y] = f.scene->patch_floor_position_mm(static_cast<int>(i));
    EXPECT_NEAR(p["center_m"][0].get<double>(), x * 1e-3, 1e-9) << p["id"];
    EXPECT_NEAR(p["center_m"][1].get<double>(), y * 1e-3, 1e-9) << p["id"];
    EXPECT_NEAR(p["size_m"].get<double>(), 0.015, 1e-9);  // the SG's 15 mm patches at a 19 mm pitch
  }
  EXPECT_EQ(s["bands"]["count"], 36);
  EXPECT_EQ(s["cabinet"]["walls_reflectance"], 0.0);
  EXPECT_EQ(s["cabinet"]["floor_reflectance"], 0.30);
  EXPECT_TRUE(s["camera"]["estimated"].get<bool>());
  EXPECT_EQ(s["luminance_scale"]["spots"].size(), 80u * 2);  // the 100 % readings of D65 and TL84
}

// CSV of the shared data set: column `name` at `nm`.
double shared_value(const std::filesystem::path& file, const std::string& name, double nm) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> cols;
  for (std::stringstream ss(line); std::getline(ss, line, ',');) cols.push_back(line);
  const auto col = std::find(cols.begin(), cols.end(), name) - cols.begin();
  while (std::getline(in, line)) {
    std::vector<double> v;
    for (std::stringstream ss(line); std::getline(ss, line, ',');) v.push_back(std::stod(line));
    if (std::abs(v[0] - nm) < 1e-9) return v[static_cast<std::size_t>(col)];
  }
  ADD_FAILURE() << name << " at " << nm << " nm not in " << file;
  return 0;
}

TEST(SceneExport, LampSpectraAreTheNamedStandardsScaledToTheFittedLuminance) {
  const auto lamps_file = paths::shared_data_file("cie_illuminants_A_D50_D65_F2_F11_5nm_380_780.csv");
  const auto cmf_file = paths::shared_data_file("cie1931_2deg_cmf_1nm_360_830.csv");
  if (!lamps_file || !cmf_file) GTEST_SKIP() << "CIE tables of ../shared/data not present";
  const auto& f = fixture();
  const json s = export_scene(default_cabinet(), {f.chart, f.grid});
  ASSERT_EQ(s["lamps"].size(), 2u);
  for (const auto& lamp : s["lamps"]) {
    const std::string name = lamp["name"], cie = name == "D65" ? "D65" : "F11";
    const auto& v = lamp["spectral_radiance"]["values"];
    // Shape: a constant multiple of the CIE table at every band centre.
    const double k = v[17].get<double>() / shared_value(*lamps_file, cie, 550.0);
    double y = 0, peak = 0;
    for (std::size_t i = 0; i < v.size(); ++i) peak = std::max(peak, shared_value(*lamps_file, cie, 380.0 + 10.0 * static_cast<double>(i)));
    for (std::size_t i = 0; i < v.size(); ++i) {
      const double nm = 380.0 + 10.0 * static_cast<double>(i);
      // colord's copy of the CIE table and the shared data set's may round differently in the last digit.
      EXPECT_NEAR(v[i].get<double>() / k, shared_value(*lamps_file, cie, nm), 1e-3 * peak) << name << " " << nm;
      y += v[i].get<double>() * shared_value(*cmf_file, "ybar", nm) * 10.0;
    }
    // Level: 683·Σ L ȳ Δλ is the lamp's luminance. The 10 nm sum misses the finer integral the export takes on
    // the 5 nm table by the sampling error of a line spectrum (F11's lines): within 3 %.
    EXPECT_NEAR(683.0 * y / lamp["luminance_cd_m2"].get<double>(), 1.0, 0.03) << name;
    EXPECT_EQ(lamp["level"]["source"], "fitted");
    EXPECT_THAT(lamp["spectrum_source"].get<std::string>(), ::testing::HasSubstr("named standard"));
  }
}

TEST(SceneExport, TheFittedLevelIsTheSimulatedEmittersLuminanceWithinTheLs110sNoise) {
  const auto& f = fixture();
  const json s = export_scene(default_cabinet(), {f.chart, f.grid}, {{"D65"}, 100.0});
  const double truth = emitter_of(default_cabinet(), "D65")->luminance_cd_m2;
  const auto& lamp = s["lamps"][0];
  // The fit's standard error comes from its own residuals (the LS-110's 0.1 % repeatability over 80 spots);
  // 4 of them leave a chance of 6e-5 of failing on a faithful export.
  const double se = lamp["level"]["standard_error_pct"].get<double>() / 100.0;
  EXPECT_GT(se, 0.0);
  EXPECT_NEAR(lamp["luminance_cd_m2"].get<double>() / truth, 1.0, 4 * se);
  EXPECT_LT(lamp["level"]["rms_residual_pct"].get<double>(), 0.5);  // the LS-110's ±0.2 % + 1 digit at 2σ
  // At 50 % the fit sees the dimmer's output (the simulator's ballast curve), not half.
  const json half = export_scene(default_cabinet(), {f.chart, f.grid}, {{"D65"}, 50.0});
  EXPECT_NEAR(half["lamps"][0]["luminance_cd_m2"].get<double>() / truth, f.scene->dimmer_output(50.0), 4 * se);
}

TEST(SceneExport, RefusesWhatCannotMakeAScene) {
  const auto& f = fixture();
  auto refused = [&](const std::vector<json>& runs, const SceneExportOptions& o, const std::string& what) {
    try {
      export_scene(default_cabinet(), runs, o);
      ADD_FAILURE() << "accepted; wanted: " << what;
    } catch (const Error& e) {
      EXPECT_THAT(e.what(), ::testing::HasSubstr(what));
    }
  };
  refused({f.grid}, {}, "no chart-read run");
  refused({f.chart, f.chart}, {}, "two chart-read runs");
  json other = f.grid;
  other["run"]["campaign"] = "luminance-spot";
  refused({f.chart, other}, {}, "is a luminance-spot run");
  refused({f.chart, f.grid}, {{"UV"}, 100.0}, "has no named standard spectrum");
  refused({f.chart, f.grid}, {{"CWF"}, 25.0}, "no LS-110 readings of CWF at 25");
  refused({json::object()}, {}, "not a run export");
  json short_chart = f.chart;
  short_chart["measurements"].erase(short_chart["measurements"].begin() + 3);
  refused({short_chart}, {}, "patch A4 was not read");
  // Without a grid run the configured luminance stands at 100 %, and says so.
  const json s = export_scene(default_cabinet(), {f.chart}, {{"CWF"}, 100.0});
  EXPECT_EQ(s["lamps"][0]["level"]["source"], "configured");
  EXPECT_EQ(s["lamps"][0]["luminance_cd_m2"], emitter_of(default_cabinet(), "CWF")->luminance_cd_m2);
}

TEST(SceneExport, TheCliWritesSceneJsonAndTheBlenderScriptFromRunFiles) {
  const auto& f = fixture();
  const auto dir = std::filesystem::temp_directory_path() / ("colorlab-scene-cli-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "chart.json") << f.chart.dump();
  std::ofstream(dir / "grid.json") << f.grid.dump();
  const std::string cmd = std::string(COLORLAB_BIN_DIR) + "/colorlab scene " + (dir / "chart.json").string() + " " +
                          (dir / "grid.json").string() + " --lamp D65 -o " + (dir / "out").string() + " > " +
                          (dir / "log").string() + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << read_file(dir / "log");
  const json s = json::parse(read_file(dir / "out" / "scene.json"));
  EXPECT_EQ(s, export_scene(default_cabinet(), {f.chart, f.grid}, {{"D65"}, 100.0}));
  EXPECT_EQ(read_file(dir / "out" / "build_scene.py"), read_file(std::filesystem::path(COLORLAB_SOURCE_DIR) / "verify/scene/build_scene.py"));
  // A bad run file is a typed refusal with a non-zero exit.
  std::ofstream(dir / "bad.json") << "{not json";
  EXPECT_NE(std::system((std::string(COLORLAB_BIN_DIR) + "/colorlab scene " + (dir / "bad.json").string() + " -o " +
                         (dir / "out2").string() + " > /dev/null 2>&1")
                            .c_str()),
            0);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace colorlab::verify
