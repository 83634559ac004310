// colorlabd's own [cabinet] (issue 23, docs/verify.md "The cabinet in the lab configuration"): read and validated
// when the configuration is, refused at start with the file's line, served at GET /v1/lab/cabinet, and used by
// `colorlab scene` for runs it fetches from that daemon when no --lab is given. The expected cabinet is the TOML
// written here, read back through verify/scene's own parser (the one `--lab FILE` uses), never the daemon's answer.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "colorlab/client/api_client.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/daemon/config.hpp"
#include "colorlab/testing/daemon.hpp"
#include "colorlab/testing/process.hpp"
#include "colorlab/testing/temp_dir.hpp"
#include "colorlab/verify/cabinet_json.hpp"
#include "colorlab/verify/cabinet_toml.hpp"
#include "colorlab/verify/lens_calibration.hpp"
#include "colorlab/verify/scene_export.hpp"
#include "located_chart_run.hpp"

namespace {

using colorlab::Error;
using colorlab::testing::DaemonProcess;
using colorlab::testing::TempDir;
using nlohmann::json;
namespace verify = colorlab::verify;

// A cabinet unlike the built-in one in every key the export uses: taller, a darker floor, one D65 panel elsewhere.
constexpr const char* kCabinet = R"([cabinet]
height_mm = 700
floor_reflectance = 0.25
chart_center_mm = [600, 160]

[[cabinet.emitter]]
lamp = "D65"
center_mm = [600, 250]
size_mm = [900, 120]
luminance_cd_m2 = 15000
)";

// The lab's lens calibration for 1752 × 1168 photographs (docs/verify.md "The lens calibration"), kept beside it.
constexpr const char* kLens = R"(
[[lens]]
camera = "simulated DSLR"
lens = "simulated 31 mm"
width_px = 1752
height_px = 1168
fx = 2450
fy = 2452
cx = 889.5
cy = 574.5
k1 = -0.09
k2 = 0.04
sigma = { fx = 13, fy = 13, cx = 6, cy = 7, k1 = 0.015, k2 = 0.12 }
source = "test"
date = "2026-11-29"
)";

// A characterize-camera run's export with the located chart's corners on a 1752 × 1168 photograph (seen
// square-on), as a file: `colorlab scene` takes run files beside run ids.
json characterize_run() {
  const double s = 1000.0 / 262.0;
  json corners = json::array({
      {876 - 131 * s, 584 - 93 * s},
      {876 + 131 * s, 584 - 93 * s},
      {876 + 131 * s, 584 + 93 * s},
      {876 - 131 * s, 584 + 93 * s},
  });
  return colorlab::verify::testing::located_chart_run(corners, 1.0, 1752, 1168, 0.2);
}

std::string read_file(const std::filesystem::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

TEST(DaemonCabinet, TheConfigurationReadsTheTableThroughTheSameParserAsLab) {
  TempDir dir;
  std::ofstream(dir / "lab.toml") << kCabinet;
  const auto c = colorlab::daemon::parse_config(kCabinet, dir / "colorlabd.toml");
  ASSERT_TRUE(c.cabinet.has_value());
  EXPECT_EQ(verify::cabinet_to_json(*c.cabinet), verify::cabinet_to_json(verify::cabinet_from_file(dir / "lab.toml")));
  EXPECT_EQ(c.cabinet->height_mm, 700);
  ASSERT_EQ(c.cabinet->emitters.size(), 1u);
  EXPECT_FALSE(colorlab::daemon::parse_config("", dir / "colorlabd.toml").cabinet.has_value());
  // JSON (the API's form) back to the geometry: the same cabinet, and a bad one refused naming the field.
  EXPECT_EQ(verify::cabinet_to_json(verify::cabinet_from_json(verify::cabinet_to_json(*c.cabinet), "test")),
            verify::cabinet_to_json(*c.cabinet));
  json bad = verify::cabinet_to_json(*c.cabinet);
  bad["emitter"][0]["size_mm"] = {900, -1};
  try {
    verify::cabinet_from_json(bad, "GET /v1/lab/cabinet");
    ADD_FAILURE() << "a negative emitter size was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), colorlab::ErrorClass::bad_data);
    EXPECT_NE(std::string(e.what()).find("GET /v1/lab/cabinet"), std::string::npos) << e.what();
  }
  bad = verify::cabinet_to_json(*c.cabinet);
  bad.erase("height_mm");
  EXPECT_THROW(verify::cabinet_from_json(bad, "x"), Error);
}

TEST(DaemonCabinet, BadGeometryIsATypedErrorNamingTheLine) {
  TempDir dir;
  struct Case {
    const char* toml;
    int line;
    const char* says;
  };
  for (const Case& c : {Case{"[cabinet]\nwidth_mm = 1200\nfloor_reflectance = 1.5\n", 1, "reflectance"},
                        Case{"[cabinet]\n\n[[cabinet.emitter]]\nlamp = \"D65\"\ncenter_mm = [600, 580]\nsize_mm = [1000, 100]\n",
                             1, "ceiling"},
                        Case{"[cabinet]\nheight = 600\n", 2, "unknown key cabinet.height"},
                        Case{"cabinet = 3\n", 1, "[cabinet] must be a table"},
                        Case{"[[lens]]\ncamera = \"A\"\nlens = \"B\"\nwidth_px = 100\nheight_px = 80\nfx = 0\nfy = 90\ncx = 49.5\ncy = 39.5\n", 1,
                             "lens: fx and fy must be > 0"},
                        Case{"lens = 3\n", 1, "[[lens]] tables"}}) {
    try {
      colorlab::daemon::parse_config(c.toml, dir / "colorlabd.toml");
      ADD_FAILURE() << "accepted:\n"
                    << c.toml;
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_EQ(e.cls(), colorlab::ErrorClass::bad_parameter) << what;
      EXPECT_NE(what.find("colorlabd.toml:" + std::to_string(c.line)), std::string::npos) << what;
      EXPECT_NE(what.find(c.says), std::string::npos) << what;
    }
  }
}

TEST(DaemonCabinet, ColorlabdRefusesToStartOnBadGeometry) {
  TempDir dir;
  std::ofstream(dir / "colorlabd.toml") << "[cabinet]\ndepth_mm = -600\n";
  const auto r = colorlab::testing::run_command(
      {colorlab::testing::bin_path("colorlabd"), "--config", (dir / "colorlabd.toml").string(), "--state",
       (dir / "state").string(), "--listen", "127.0.0.1:0"},
      std::chrono::seconds(60));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("colorlabd.toml:1"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("depth"), std::string::npos) << r.err;
}

TEST(DaemonCabinet, SceneAgainstTheDaemonUsesItsCabinetWithoutLab) {
  TempDir dir;
  std::ofstream(dir / "lab.toml") << "[genicam]\nenabled = false\n";
  std::ofstream(dir / "colorlabd.toml") << "[simulator]\nenabled = true\ntime_scale = 1000\nseed = 5\nconfig = \"lab.toml\"\n\n"
                                        << kCabinet << kLens;
  std::ofstream(dir / "cabinet.toml") << kCabinet << kLens;
  std::ofstream(dir / "characterize.json") << characterize_run().dump();
  const verify::CabinetGeometry expected = verify::cabinet_from_file(dir / "cabinet.toml");
  const auto lenses = verify::lenses_from_file((dir / "cabinet.toml").string());
  DaemonProcess daemon(dir / "state", dir / "colorlabd.toml");
  colorlab::client::Endpoint ep;
  ep.unix_socket = daemon.unix_socket();
  const colorlab::client::ApiClient api(ep, std::chrono::seconds(30));

  const json served = api.get("/v1/lab/cabinet");
  EXPECT_EQ(served["source"], "config");
  EXPECT_EQ(served["cabinet"], verify::cabinet_to_json(expected));
  // The lens calibration: served as the same table reads through --lab's parser, listed by the CLI.
  ASSERT_EQ(lenses.size(), 1u);
  EXPECT_EQ(api.get("/v1/lab/lenses"), json({{"items", json::array({verify::lens_to_json(lenses[0])})}}));
  const auto listed = colorlab::testing::run_command({colorlab::testing::bin_path("colorlab"), "--socket", daemon.unix_socket(),
                                                      "--json", "lens", "list"},
                                                     std::chrono::seconds(60));
  ASSERT_EQ(listed.exit_code, 0) << listed.err;
  EXPECT_EQ(json::parse(listed.out)["items"], json::array({verify::lens_to_json(lenses[0])}));

  // A chart-read (140 patches, about 2 s at time scale 1000) to export.
  const json e = api.post("/v1/executions", {{"campaign", "chart-read"}, {"params", json::object()}});
  json done;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  for (;;) {
    done = api.get("/v1/executions/" + e["id"].get<std::string>());
    if (done["status"].get<std::string>().rfind("finished", 0) == 0 || done["status"] == "aborted") break;
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "chart-read did not finish in 120 s: " << done.dump();
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_EQ(done["status"], "finished_ok") << done.dump();
  const std::string run = done["run_id"].get<std::string>();

  const auto r = colorlab::testing::run_command({colorlab::testing::bin_path("colorlab"), "--socket", daemon.unix_socket(),
                                                 "--json", "scene", run, (dir / "characterize.json").string(), "--lamp", "D65",
                                                 "-o", (dir / "out").string()},
                                                std::chrono::seconds(60));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json::parse(r.out)["cabinet"], "daemon (config)") << r.out;
  EXPECT_EQ(json::parse(r.out)["lens_calibrations"], "daemon") << r.out;
  // The whole scene is what the export makes of that cabinet and the stored run (as --lab FILE would give).
  const json chart = json::parse(
      api.request("GET", "/v1/runs/" + run + "/export?format=json").body);
  const json scene = json::parse(read_file(dir / "out" / "scene.json"));
  // The camera's intrinsics: the daemon's stored calibration for the located photograph's size, by default.
  EXPECT_EQ(scene, verify::export_scene(expected, {chart, characterize_run()}, {{"D65"}, 100.0, std::nullopt, "", lenses, ""}));
  EXPECT_EQ(scene["camera"]["lens_calibration"]["name"], "simulated DSLR / simulated 31 mm") << scene["camera"].dump();
  EXPECT_FALSE(scene["camera"]["estimated"].get<bool>());
  EXPECT_DOUBLE_EQ(scene["cabinet"]["height_m"].get<double>(), 0.7) << scene["cabinet"].dump();
  EXPECT_DOUBLE_EQ(scene["cabinet"]["floor_reflectance"].get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(scene["lamps"][0]["luminance_cd_m2"].get<double>(), 15000);
}

}  // namespace
