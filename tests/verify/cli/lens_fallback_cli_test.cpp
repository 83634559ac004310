// `colorlab verify` and `colorlab scene` against a daemon that does not serve GET /v1/lab/lenses (an older colorlabd,
// a fleet's central API: the route answers 404). Issue 23's loose end: such a daemon holds no calibration the CLI
// could use, so both fall back to what they do when the lab has none — the floor placed as a pinhole's, the nominal
// lens — and say why; every other refusal of the route (401, 5xx, an answer that is not the route's) stays an error,
// because passing it off as "no calibration" would hide a wrong key or a broken daemon behind a misplaced floor.
// The daemon is a stand-in (fake_daemon.hpp) serving hand-made runs shaped as floor-luminance, chart-read and
// characterize-camera store them; the truth for the fallback is the CLI's own answer when the route lists no
// calibration (the same placement, value for value) and, for the scene, export_scene without calibrations in process.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "colorlab/sim/scene.hpp"
#include "colorlab/testing/process.hpp"
#include "colorlab/testing/temp_dir.hpp"
#include "colorlab/verify/cabinet.hpp"
#include "colorlab/verify/cabinet_json.hpp"
#include "colorlab/verify/lens_calibration.hpp"
#include "colorlab/verify/rendering.hpp"
#include "ramp_rendering.hpp"
#include "colorlab/verify/scene_export.hpp"
#include "fake_daemon.hpp"
#include "located_chart_run.hpp"
#include "simulated_runs.hpp"

namespace colorlab::verify {
namespace {

using nlohmann::json;
using colorlab::testing::bin_path;
using colorlab::testing::run_command;
using colorlab::testing::TempDir;
using testing::FakeDaemon;
using cli_testing::ramp;
using cli_testing::rendered;

// An answer the lens route must not be taken as "no calibrations" from: the exit status and words it must give.
struct Refusal {
  FakeDaemon::Answer answer;
  int exit_code;
  const char* words;
};

constexpr const char* kFloorRun = "0193c0de-0000-7000-8000-0000000f1009";
constexpr const char* kLensRoute = "/v1/lab/lenses";

// A floor-luminance run as the campaign stores it (docs/campaigns.md): its photograph row (the floor's corners on a
// 3504 × 2336 photograph seen from the cabinet's open front) and a 2 × 3 map.
void serve_floor_run(FakeDaemon& d) {
  json m = json::array();
  json photo = json::object();
  photo["lamp"] = "D65";
  photo["dimmer_percent"] = 100;
  photo["width"] = 3504;
  photo["height"] = 2336;
  photo["corners_px"] = json::parse("[[300, 2100], [3200, 2100], [2900, 400], [600, 400]]");
  photo["spot_mm"] = 20;
  photo["calibration"] = json::parse(R"([{"residual_pct": 1.0}, {"residual_pct": -1.5}])");
  photo["grid_rows"] = 2;
  photo["grid_cols"] = 3;
  m.push_back({{"step", "P/D65/D100"}, {"quantity", "floor_photograph"}, {"value", 1.0}, {"data", photo}});
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 3; ++c)
      m.push_back({{"step", "F/D65/D100/r" + std::to_string(r) + "c" + std::to_string(c)},
                   {"quantity", "luminance"},
                   {"value", 100.0 + 10 * r + c},
                   {"unit", "cd/m2"},
                   {"data", {{"row", r}, {"col", c}, {"lamp", "D65"}, {"dimmer_percent", 100}}}});
  const std::string base = std::string("/v1/runs/") + kFloorRun;
  d.answer(base, {200, json{{"id", kFloorRun}, {"campaign", "floor-luminance"}, {"status", "finished_ok"}, {"params", json::object()}}.dump()});
  d.answer(base + "/measurements", {200, json{{"items", m}, {"next_cursor", nullptr}}.dump()});
}

// A barrel lens for the floor photograph's size: placing through it moves the sampled regions.
LensCalibration barrel(int width, int height, double fx, double cx, double cy) {
  LensCalibration l;
  l.camera = "sim", l.lens = "barrel", l.width_px = width, l.height_px = height;
  l.intrinsics = {fx, fx, cx, cy, -0.10, 0.02};
  l.sigma = {4, 4, 2, 2, 0.001, 0.01};
  l.source = "test", l.date = "2026-11-29";
  return l;
}

json items(const std::vector<LensCalibration>& lenses) {
  json a = json::array();
  for (const auto& l : lenses) a.push_back(lens_to_json(l));
  return json{{"items", a}};
}

std::string problem(int status, const std::string& code) {
  return json{{"type", "about:blank"}, {"title", code}, {"status", status}, {"detail", code}, {"category", "auth"}, {"code", code}}.dump();
}

TEST(VerifyLensFallback, APinholeSaidSoWhenTheDaemonServesNoLensesAndOtherRefusalsStayErrors) {
  TempDir dir;
  FakeDaemon daemon;
  serve_floor_run(daemon);
  write_openexr(ramp(1752, 1168), dir / "ramp.exr");  // half the photograph: places scale with it
  const auto cli = [&](std::vector<std::string> extra = {}) {
    std::vector<std::string> argv{bin_path("colorlab"), "--url", daemon.url(), "verify", (dir / "ramp.exr").string(),
                                  "--against", kFloorRun, "--json", "--scale", "1"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return run_command(argv, std::chrono::seconds(30));
  };

  // The lab's answer that it has no calibration: the pinhole placement, the reference for the fallback.
  daemon.answer(kLensRoute, {200, items({}).dump()});
  const auto none = cli();
  ASSERT_TRUE(none.exit_code == 0 || none.exit_code == 4) << none.err;
  const json n = json::parse(none.out);
  ASSERT_EQ(n["placement"]["light"]["model"], "pinhole") << n["placement"].dump();

  // No route: the same placement, value for value, and the reason in `how`.
  daemon.forget(kLensRoute);
  daemon.clear_asked();
  const auto absent = cli();
  ASSERT_TRUE(absent.exit_code == 0 || absent.exit_code == 4) << absent.err;
  const json a = json::parse(absent.out);
  EXPECT_EQ(a["placement"]["light"]["model"], "pinhole");
  EXPECT_TRUE(a["placement"]["light"]["lens"].is_null());
  const std::string how = a["placement"]["light"]["how"].get<std::string>();
  EXPECT_NE(how.find("the daemon serves no lens calibrations (GET /v1/lab/lenses: 404)"), std::string::npos) << how;
  EXPECT_EQ(rendered(a), rendered(n));
  EXPECT_EQ(a["summary"], n["summary"]);
  const auto asked = daemon.asked();
  EXPECT_NE(std::find(asked.begin(), asked.end(), kLensRoute), asked.end()) << "the route was never asked";
  // Printed for a person too.
  const auto human = run_command({bin_path("colorlab"), "--url", daemon.url(), "verify", (dir / "ramp.exr").string(), "--against",
                                  kFloorRun, "--scale", "1"},
                                 std::chrono::seconds(30));
  EXPECT_NE(human.out.find("floor placed: the daemon serves no lens calibrations"), std::string::npos) << human.out << human.err;
  // A calibration named where the daemon serves none cannot be honoured: refused, naming it.
  const auto named = cli({"--lens-calibration", "sim / barrel"});
  EXPECT_EQ(named.exit_code, 1) << named.out;
  EXPECT_NE(named.err.find("sim / barrel"), std::string::npos) << named.err;
  EXPECT_NE(named.err.find("404"), std::string::npos) << named.err;
  // --lens needs no daemon calibration: the route is not asked.
  daemon.clear_asked();
  const auto given = cli({"--lens", "3900,3900,1751.5,1167.5,-0.1,0.02"});
  ASSERT_TRUE(given.exit_code == 0 || given.exit_code == 4) << given.err;
  EXPECT_EQ(json::parse(given.out)["placement"]["light"]["model"], "lens calibration");
  for (const auto& p : daemon.asked()) EXPECT_NE(p, kLensRoute);

  // The route served with a calibration of the photograph's size: used (so the stand-in's route is the one read).
  daemon.answer(kLensRoute, {200, items({barrel(3504, 2336, 3900, 1751.5, 1167.5)}).dump()});
  const auto served = cli();
  ASSERT_TRUE(served.exit_code == 0 || served.exit_code == 4) << served.err;
  const json s = json::parse(served.out);
  EXPECT_EQ(s["placement"]["light"]["model"], "lens calibration");
  EXPECT_NE(rendered(s), rendered(n));

  // Every other refusal is an error: the API's (exit 2) with its status, or a local one (exit 1) for an answer that
  // is not the route's — never a pinhole placement.
  const Refusal refusals[] = {
      {{401, problem(401, "unauthorized"), "application/problem+json"}, 2, "401"},
      {{403, problem(403, "forbidden"), "application/problem+json"}, 2, "403"},
      {{503, problem(503, "unavailable"), "application/problem+json"}, 2, "503"},
      {{500, "<html>proxy error</html>", "text/html"}, 2, "500"},
      {{200, "not json at all"}, 1, "invalid JSON"},
      {{200, R"({"lenses": []})"}, 1, "no items"},
      {{200, R"({"items": [{"camera": "x"}]})"}, 1, "GET /v1/lab/lenses"},
  };
  for (const auto& r : refusals) {
    daemon.answer(kLensRoute, r.answer);
    const auto got = cli();
    EXPECT_EQ(got.exit_code, r.exit_code) << r.answer.status << " " << r.answer.body << ": " << got.out << got.err;
    EXPECT_NE(got.err.find(r.words), std::string::npos) << r.answer.body << ": " << got.err;
    EXPECT_EQ(got.out.find("pinhole"), std::string::npos) << got.out;
  }
}

TEST(SceneLensFallback, TheNominalLensSaidSoWhenTheDaemonServesNoLensesAndOtherRefusalsStayErrors) {
  TempDir dir;
  FakeDaemon daemon;
  sim::SceneConfig sc;
  sc.seed = 4;
  sc.lamps_on_at_start = {sim::Lamp::d65};
  sim::Scene scene(sc, std::make_shared<sim::SimClock>());
  const json chart = testing::chart_read_run(scene, 1);
  const std::string chart_id = chart["run"]["id"].get<std::string>();
  daemon.answer("/v1/runs/" + chart_id + "/export", {200, chart.dump()});
  daemon.answer("/v1/lab/cabinet", {200, json{{"source", "default"}, {"cabinet", cabinet_to_json(default_cabinet())}}.dump()});
  // The chart located square-on on a 1752 × 1168 photograph, 1000 px across its 262 mm: the pose the scene's camera
  // takes, through whichever lens the lab has for that size.
  const double k = 1000.0 / 262.0;
  const json located = testing::located_chart_run(
      {{876 - 131 * k, 584 - 93 * k}, {876 + 131 * k, 584 - 93 * k}, {876 + 131 * k, 584 + 93 * k}, {876 - 131 * k, 584 + 93 * k}}, 1.0,
      1752, 1168, 0.2);
  std::ofstream(dir / "char.json") << located.dump();
  const auto cli = [&](std::vector<std::string> extra = {}) {
    std::vector<std::string> argv{bin_path("colorlab"), "--json", "--url", daemon.url(), "scene", chart_id, (dir / "char.json").string(),
                                  "--lamp", "D65", "-o", (dir / "out").string()};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return run_command(argv, std::chrono::seconds(60));
  };
  const auto written = [&] {
    std::ifstream f(dir / "out" / "scene.json");
    std::stringstream ss;
    ss << f.rdbuf();
    return json::parse(ss.str());
  };
  const std::vector<json> runs{chart, located};

  // No route: the nominal lens, exactly the scene exported with no calibration, and the reason said.
  const auto absent = cli();
  ASSERT_EQ(absent.exit_code, 0) << absent.err;
  const json said = json::parse(absent.out);
  EXPECT_EQ(said["lens_calibrations"], "none (the daemon serves no lens calibrations (GET /v1/lab/lenses: 404))");
  const json nominal = written();
  EXPECT_EQ(nominal, export_scene(default_cabinet(), runs, {{"D65"}, 100.0, std::nullopt, "", {}, ""}));
  EXPECT_TRUE(nominal["camera"]["lens_calibration"].is_null());
  const auto named = cli({"--lens-calibration", "sim / barrel"});
  EXPECT_EQ(named.exit_code, 1);
  EXPECT_NE(named.err.find("404"), std::string::npos) << named.err;

  // Served with a calibration of the photograph's size: used and named (the stand-in's route is the one read).
  const LensCalibration l = barrel(1752, 1168, 2450, 875.5, 583.5);
  daemon.answer(kLensRoute, {200, items({l}).dump()});
  const auto served = cli();
  ASSERT_EQ(served.exit_code, 0) << served.err;
  EXPECT_EQ(json::parse(served.out)["lens_calibrations"], "daemon");
  EXPECT_EQ(written()["camera"]["lens_calibration"]["name"], l.name());

  // Every other refusal is an error, and nothing is written in its place.
  const Refusal refusals[] = {
      {{401, problem(401, "unauthorized"), "application/problem+json"}, 2, "401"},
      {{503, problem(503, "unavailable"), "application/problem+json"}, 2, "503"},
      {{200, "not json at all"}, 1, "invalid JSON"},
      {{200, R"({"lenses": []})"}, 1, "no items"},
  };
  for (const auto& r : refusals) {
    std::filesystem::remove_all(dir / "out");
    daemon.answer(kLensRoute, r.answer);
    const auto got = cli();
    EXPECT_EQ(got.exit_code, r.exit_code) << r.answer.body << ": " << got.out << got.err;
    EXPECT_NE(got.err.find(r.words), std::string::npos) << r.answer.body << ": " << got.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "out" / "scene.json")) << r.answer.body;
  }
}

}  // namespace
}  // namespace colorlab::verify
