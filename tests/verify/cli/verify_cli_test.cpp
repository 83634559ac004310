// `colorlab verify` end to end (issue 23, docs/verify.md "Using it"): colorlabd with its embedded simulated lab runs
// a short cabinet-grid and floor-luminance; the test writes an XYZ OpenEXR rendering whose luminance is the
// simulator's own true floor field (floor_truth: each spot's noiseless luminance, independent of the camera, the
// meter and the flat field the runs measured through), and the CLI compares it with the runs. Bounds from the issue:
// a faithful rendering agrees at ≥ 95 % of the spots; a lamp 10 % too bright with the scale given is flagged.
#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <map>
#include <optional>
#include <random>
#include <stdexcept>
#include <utility>
#include <fstream>

#include <gtest/gtest.h>
#include <sqlite3.h>

#include "colorlab/analysis/floor_luminance.hpp"
#include "colorlab/sim/control_channel.hpp"
#include "colorlab/verify/rendering.hpp"
#include "resume_support.hpp"

using namespace colorlab;
using namespace colorlab::testing;
using nlohmann::json;

namespace {

// 20 spots: both campaigns in a few seconds at time scale 200
constexpr int kRows = 4, kCols = 5;
constexpr double kPitchX = 60, kPitchY = 54, kFloorW = 1200, kFloorD = 600;  // the §6.2 grid (docs/simulator.md)

json control(const DaemonProcess& daemon, const json& command) {
  json endpoint = json::parse(std::ifstream(daemon.state_dir() / "colorlabd.endpoint"));
  return sim::send_control_command(endpoint.at("simulator_control").get<std::string>(), command);
}

// The true floor as an image from the photograph's view: each pixel mapped to the floor and given the true
// luminance of the grid cell it falls in (piecewise constant, so a spot's region, well inside its 60 × 54 mm cell,
// sees exactly its spot's truth). XYZ with the D65 white's chromaticity; Y in cd/m², so the scale is 1.
// `textured`: every pixel gets a path tracer's 2 % relative noise (seeded), and that grid cell a ±30 % pixel
// checkerboard around its truth on top (its mean unchanged): the texture the rendering-noise screen must judge on its
// own, among neighbours whose noise it can pool.
verify::Rendering true_floor(const json& truth, double gain, std::optional<std::pair<int, int>> textured = std::nullopt) {
  std::mt19937 draw(23);
  std::normal_distribution<double> noise(0.0, 0.02);
  std::array<std::array<double, 2>, 4> corners{};
  for (int i = 0; i < 4; ++i) corners[i] = {truth["floor_corners_px"][i][0].get<double>(), truth["floor_corners_px"][i][1].get<double>()};
  const analysis::FloorMap map(corners, kFloorW, kFloorD);
  std::map<std::pair<int, int>, double> lum;
  for (const auto& s : truth["spots"]) lum[{s["row"].get<int>(), s["col"].get<int>()}] = s["luminance"].get<double>();
  verify::Rendering r;
  r.width = truth["width"].get<int>();
  r.height = truth["height"].get<int>();
  r.encoding = verify::Encoding::xyz;
  r.units = "cd/m^2";
  r.pixels.resize(static_cast<std::size_t>(r.width) * r.height * 3);
  for (int y = 0; y < r.height; ++y)
    for (int x = 0; x < r.width; ++x) {
      const auto f = map.floor_of(x, y);
      const int col = std::clamp(static_cast<int>(std::floor(f[0] / kPitchX)), 0, 19);
      const int row = std::clamp(static_cast<int>(std::floor(f[1] / kPitchY)), 0, 7);
      double texture = 1.0;
      if (textured) texture = (*textured == std::pair{row, col} ? ((x + y) % 2 ? 1.3 : 0.7) : 1.0) * (1.0 + noise(draw));
      const double Y = gain * texture * lum.at({row, col});
      float* p = r.pixels.data() + (static_cast<std::size_t>(y) * r.width + x) * 3;
      p[0] = static_cast<float>(Y * 0.95047), p[1] = static_cast<float>(Y), p[2] = static_cast<float>(Y * 1.08883);
    }
  return r;
}

struct Kind {
  int compared = 0, differ = 0;
};

std::map<std::string, Kind> tally(const json& result) {
  std::map<std::string, Kind> k;
  for (const auto& c : result["comparisons"]) {
    auto& t = k[c["kind"].get<std::string>()];
    ++t.compared;
    if (c["verdict"] == "differs") ++t.differ;
  }
  return k;
}

struct Lab {
  static void start() {
    dir_ = new TempDir;
    auto config = write_daemon_config(dir_->path(), 200, 11);
    daemon_ = new DaemonProcess(dir_->path() / "state", config);
    auto api = api_for(*daemon_);
    // run_to_end waits for the campaign, as the other embedded-lab tests do (the instruments come up on their own).
    // The floor's corners as a bench would measure them on its photograph: the simulator's, as fractions.
    const json t = control(*daemon_, {{"cmd", "floor_truth"}, {"instrument", "dslr"}});
    json corners = json::array();
    for (const auto& c : t["floor_corners_px"]) {
      corners.push_back((c[0].get<double>() + 0.5) / t["width"].get<double>());
      corners.push_back((c[1].get<double>() + 0.5) / t["height"].get<double>());
    }
    const json light = {{"lamps", {"D65"}}, {"dimmer_levels", {100}}, {"settle_s", 0}, {"rows", kRows}, {"cols", kCols}};
    json g = light;
    g["readings"] = 2;
    grid_ = new std::string(run_to_end(api, "cabinet-grid", g)["id"].get<std::string>());
    json f = light;
    f["frames"] = 4;
    f["corners"] = corners;
    f["grid_run"] = *grid_;
    floor_ = new std::string(run_to_end(api, "floor-luminance", f)["id"].get<std::string>());
    // The truth now: the campaigns left D65 lit at 100 %.
    truth_ = new json(control(*daemon_, {{"cmd", "floor_truth"}, {"instrument", "dslr"}}));
    verify::write_openexr(true_floor(*truth_, 1.0), dir_->path() / "faithful.exr");
    verify::write_openexr(true_floor(*truth_, 1.1), dir_->path() / "brighter.exr");
    std::ofstream(dir_->path() / "bad.exr") << "v/1 this is no image";
  }
  static void stop() {
    delete daemon_;
    delete dir_;
    delete grid_;
    delete floor_;
    delete truth_;
    daemon_ = nullptr, dir_ = nullptr, grid_ = nullptr, floor_ = nullptr, truth_ = nullptr;
  }

  static RunResult cli(std::vector<std::string> args) {
    std::vector<std::string> argv{bin_path("colorlab"), "--socket", daemon_->unix_socket()};
    argv.insert(argv.end(), args.begin(), args.end());
    return run_command(argv, std::chrono::seconds(60));
  }
  static std::vector<std::string> verify_args(const std::string& file) {
    return {"verify", (dir_->path() / file).string(), "--against", *grid_, *floor_, "--json", "--scale", "1"};
  }

  static inline TempDir* dir_ = nullptr;
  static inline DaemonProcess* daemon_ = nullptr;
  static inline std::string* grid_ = nullptr;
  static inline std::string* floor_ = nullptr;
  static inline json* truth_ = nullptr;
};

// Lab's members, as the checks below name them.
const auto& dir_ = Lab::dir_;
const auto& daemon_ = Lab::daemon_;
const auto& grid_ = Lab::grid_;
const auto& floor_ = Lab::floor_;
const auto& truth_ = Lab::truth_;
RunResult cli(std::vector<std::string> args) { return Lab::cli(std::move(args)); }
std::vector<std::string> verify_args(const std::string& file) { return Lab::verify_args(file); }

void the_true_floor_agrees_at_95_percent_of_the_spots() {
  ASSERT_EQ((*truth_)["dimmer"].get<double>(), 100) << truth_->dump();
  const auto r = cli(verify_args("faithful.exr"));
  ASSERT_TRUE(r.exit_code == 0 || r.exit_code == 4) << r.exit_code << "\n"
                                                    << r.err;
  const json result = json::parse(r.out);
  const auto k = tally(result);
  ASSERT_EQ(k.at("light_spot").compared, kRows * kCols);
  ASSERT_EQ(k.at("light_floor").compared, kRows * kCols);
  for (const auto& [kind, t] : k) {
    const double agree = 1.0 - static_cast<double>(t.differ) / t.compared;
    std::cout << kind << ": " << t.compared - t.differ << "/" << t.compared << " agree\n";
    EXPECT_GE(agree, 0.95) << kind << "\n"
                           << result["summary"].dump(2);
  }
  // The margin, printed for the record: the largest distance over its threshold (1 = the band's edge).
  double worst = 0;
  for (const auto& c : result["comparisons"]) worst = std::max(worst, c["mahalanobis"].get<double>() / c["threshold"].get<double>());
  std::cout << "largest distance / threshold: " << worst << "\n";
  for (const auto& s : result["summary"]["scales"]) EXPECT_EQ(s["how"], "given") << s.dump();
  // The exit status is the verdict: 0 exactly when every comparison agrees.
  const bool any = std::any_of(k.begin(), k.end(), [](const auto& e) { return e.second.differ > 0; });
  EXPECT_EQ(r.exit_code, any ? 4 : 0);
  EXPECT_EQ(result["exit_status"], r.exit_code);
  EXPECT_EQ(result["summary"]["verdict"], any ? "differs" : "agrees");
}

void a_lamp_ten_percent_too_bright_differs_and_exits_4() {
  const auto r = cli(verify_args("brighter.exr"));
  ASSERT_EQ(r.exit_code, 4) << r.err << r.out.substr(0, 2000);
  const json result = json::parse(r.out);
  const auto k = tally(result);
  // 10 % against a band of about 2.5 % (LS-110, drift bound, flat field): every spot and cell flags it.
  EXPECT_EQ(k.at("light_spot").differ, kRows * kCols) << result["summary"].dump(2);
  EXPECT_EQ(k.at("light_floor").differ, kRows * kCols) << result["summary"].dump(2);
  for (const auto& c : result["comparisons"]) EXPECT_GT(c["difference"].get<double>(), 0.05) << c.dump();
  // Without the scale one fitted factor takes the level up: it must say it was fitted.
  auto args = verify_args("brighter.exr");
  args.resize(args.size() - 2);
  const auto fitted = cli(args);
  ASSERT_TRUE(fitted.exit_code == 0 || fitted.exit_code == 4) << fitted.err;
  const json fitted_result = json::parse(fitted.out);  // held: a range-for over a temporary's member reads freed memory
  for (const auto& s : fitted_result["summary"]["scales"]) EXPECT_EQ(s["how"], "fitted") << s.dump();
}

void bad_inputs_are_typed_errors_with_their_exit_codes() {
  // Not an image: a local error, exit 1, naming the file.
  const auto bad = cli(verify_args("bad.exr"));
  EXPECT_EQ(bad.exit_code, 1) << bad.out << bad.err;
  EXPECT_NE(bad.err.find("bad.exr"), std::string::npos) << bad.err;
  EXPECT_TRUE(bad.out.empty()) << bad.out;
  // A file that is not there: exit 1 before the daemon is asked.
  const auto missing = cli(verify_args("nowhere.exr"));
  EXPECT_EQ(missing.exit_code, 1) << missing.err;
  // A run the daemon does not have: the API refused, exit 2.
  const auto unknown = cli({"verify", (dir_->path() / "faithful.exr").string(), "--against", "0123456789abcdef", "--json"});
  EXPECT_EQ(unknown.exit_code, 2) << unknown.err;
  // Only a cabinet-grid run: nothing says where the floor lies in the view.
  const auto no_floor = cli({"verify", (dir_->path() / "faithful.exr").string(), "--against", *grid_});
  EXPECT_EQ(no_floor.exit_code, 1) << no_floor.err;
  EXPECT_NE(no_floor.err.find("floor-luminance"), std::string::npos) << no_floor.err;
  // A lamp the runs did not measure.
  auto args = verify_args("faithful.exr");
  args.insert(args.end(), {"--lamp", "TL84", "--dimmer", "100"});
  const auto lamp = cli(args);
  EXPECT_EQ(lamp.exit_code, 1) << lamp.err;
  EXPECT_NE(lamp.err.find("TL84"), std::string::npos) << lamp.err;
}

void store_makes_a_run_readable_through_the_api() {
  auto args = verify_args("brighter.exr");
  args.push_back("--store");
  const auto r = cli(args);
  ASSERT_EQ(r.exit_code, 4) << r.err;
  const json result = json::parse(r.out);
  const std::string id = result.at("stored_run");
  auto api = api_for(*daemon_);
  const json run = client::fetch_run(api, id);
  EXPECT_EQ(run["campaign"], "verify");
  EXPECT_EQ(run["status"], "finished_ok");
  EXPECT_EQ(run["params"]["rendering"], "brighter.exr");
  EXPECT_EQ(run["params"]["against"], json({*grid_, *floor_}));
  EXPECT_EQ(run["params"]["scale"], 1.0);
  ASSERT_EQ(run["measurements"].size(), result["comparisons"].size());
  for (std::size_t i = 0; i < run["measurements"].size(); ++i) {
    const auto& m = run["measurements"][i];
    const auto& c = result["comparisons"][i];
    EXPECT_EQ(m["step"], c["kind"].get<std::string>() + "/" + c["where"].get<std::string>());
    EXPECT_EQ(m["data"]["verdict"], c["verdict"]);
  }
  // A body whose verdict contradicts its own distance is refused, naming the field.
  json body = {{"rendering", "x.exr"}, {"against", {*grid_}}, {"scale", 1}, {"k", 2}, {"result", result}};
  body["result"]["comparisons"][0]["verdict"] = "agrees";
  try {
    api.post("/v1/verifications", body);
    ADD_FAILURE() << "a contradicting verdict was stored";
  } catch (const client::ApiError& e) {
    EXPECT_EQ(e.problem().status, 400);
    EXPECT_NE(e.problem().detail.find("comparisons[0].verdict"), std::string::npos) << e.problem().detail;
  }
}

// The rendering's own noise, off or pooled over another count: from the CLI into the result and the stored run's
// params, and through the API's body; a count below 1 and a mistyped field are typed errors (exit 1 / a 400 naming
// the field).
void rendering_noise_options_are_recorded_and_checked() {
  auto api = api_for(*daemon_);
  auto off = verify_args("faithful.exr");
  off.insert(off.end(), {"--no-rendering-noise", "--store"});
  const auto r = cli(off);
  ASSERT_TRUE(r.exit_code == 0 || r.exit_code == 4) << r.err;
  const json result = json::parse(r.out);
  EXPECT_EQ(result["rendering_noise"], false);
  EXPECT_TRUE(result["noise_neighbours"].is_null());
  for (const auto& c : result["comparisons"]) EXPECT_FALSE(c["budget"].contains("rendering noise")) << c.dump();
  const json run = client::fetch_run(api, result.at("stored_run").get<std::string>());
  EXPECT_EQ(run["params"]["rendering_noise"], false) << run["params"].dump();
  EXPECT_TRUE(run["params"]["noise_neighbours"].is_null()) << run["params"].dump();
  EXPECT_TRUE(result.contains("noise_pooling") && result["noise_pooling"].is_null()) << result.dump().substr(0, 300);
  EXPECT_TRUE(run["params"].contains("noise_pooling") && run["params"]["noise_pooling"].is_null()) << run["params"].dump();

  auto four = verify_args("faithful.exr");
  four.insert(four.end(), {"--noise-neighbours", "4", "--store"});
  const auto r4 = cli(four);
  ASSERT_TRUE(r4.exit_code == 0 || r4.exit_code == 4) << r4.err;
  const json result4 = json::parse(r4.out);
  for (const auto& c : result4["comparisons"]) EXPECT_TRUE(c["budget"].contains("rendering noise")) << c.dump();
  const json run4 = client::fetch_run(api, result4.at("stored_run").get<std::string>());
  EXPECT_EQ(run4["params"]["rendering_noise"], true) << run4["params"].dump();
  EXPECT_EQ(run4["params"]["noise_neighbours"], 4) << run4["params"].dump();
  EXPECT_EQ(result4["noise_pooling"], "median-screen");
  EXPECT_EQ(run4["params"]["noise_pooling"], "median-screen") << run4["params"].dump();
  for (const auto& c : result4["comparisons"]) EXPECT_TRUE(c.at("noise_left_out").is_boolean()) << c.dump();
  for (const auto& [kind, k] : result4["summary"]["kinds"].items())
    EXPECT_TRUE(k.at("rendering_noise_left_out").is_array()) << kind;

  for (const char* n : {"0", "-2"}) {
    auto bad = verify_args("faithful.exr");
    bad.insert(bad.end(), {"--noise-neighbours", n});
    const auto rb = cli(bad);
    EXPECT_EQ(rb.exit_code, 1) << n << ": " << rb.err;
    EXPECT_NE(rb.err.find("noise_neighbours must be at least 1"), std::string::npos) << rb.err;
    EXPECT_TRUE(rb.out.empty()) << rb.out;
  }

  // The API: a body with the options is stored with them; a bad value is a 400 naming the field.
  json body = {{"rendering", "x.exr"}, {"against", {*grid_}}, {"scale", 1}, {"k", 2}, {"result", result}, {"rendering_noise", false}};
  const json stored = api.post("/v1/verifications", body);
  const json run_api = client::fetch_run(api, stored.at("run_id").get<std::string>());
  EXPECT_EQ(run_api["params"]["rendering_noise"], false) << run_api["params"].dump();
  EXPECT_TRUE(run_api["params"]["noise_neighbours"].is_null()) << run_api["params"].dump();
  body["rendering_noise"] = true;
  body["noise_neighbours"] = 12;
  const json run12 = client::fetch_run(api, api.post("/v1/verifications", body).at("run_id").get<std::string>());
  EXPECT_EQ(run12["params"]["noise_neighbours"], 12) << run12["params"].dump();
  // A body without noise_pooling (a client from before it): its pooling not recorded.
  EXPECT_TRUE(run12["params"].contains("noise_pooling") && run12["params"]["noise_pooling"].is_null()) << run12["params"].dump();
  // JSON's one number type: 8.0 (a Python float, a JavaScript number) is the whole number 8.
  body["noise_neighbours"] = 8.0;
  ASSERT_NE(body.dump().find("\"noise_neighbours\":8.0"), std::string::npos);
  const json run8 = client::fetch_run(api, api.post("/v1/verifications", body).at("run_id").get<std::string>());
  EXPECT_TRUE(run8["params"]["noise_neighbours"].is_number_integer()) << run8["params"].dump();
  EXPECT_EQ(run8["params"]["noise_neighbours"], 8) << run8["params"].dump();

  // A verification stored before noise_pooling existed: its row's params without the key (as the store holds such a
  // row) read back with it null — not recorded — through the run and the run list.
  {
    const std::string id = result4.at("stored_run").get<std::string>();
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open_v2((daemon_->state_dir() / "colorlab.db").c_str(), &db, SQLITE_OPEN_READWRITE, nullptr), SQLITE_OK);
    sqlite3_busy_timeout(db, 10000);
    sqlite3_stmt* st = nullptr;
    ASSERT_EQ(sqlite3_prepare_v2(db, "UPDATE runs SET params = json_remove(params, '$.noise_pooling') WHERE id = ?1", -1, &st, nullptr), SQLITE_OK);
    sqlite3_bind_text(st, 1, id.c_str(), -1, SQLITE_TRANSIENT);
    EXPECT_EQ(sqlite3_step(st), SQLITE_DONE);
    sqlite3_finalize(st);
    EXPECT_EQ(sqlite3_changes(db), 1);
    sqlite3_close(db);
    const json old = api.get("/v1/runs/" + id);
    ASSERT_TRUE(old["params"].contains("noise_pooling")) << old["params"].dump();
    EXPECT_TRUE(old["params"]["noise_pooling"].is_null()) << old["params"].dump();
    EXPECT_EQ(old["params"]["noise_neighbours"], 4) << old["params"].dump();
    bool listed = false;
    const json list = api.get("/v1/runs?campaign=verify&limit=100");
    for (const auto& r : list["items"])
      if (r["id"] == id) {
        listed = true;
        EXPECT_TRUE(r["params"].contains("noise_pooling") && r["params"]["noise_pooling"].is_null()) << r["params"].dump();
      }
    EXPECT_TRUE(listed) << list.dump().substr(0, 1500);
  }
  const std::pair<json, std::string> bad_bodies[] = {
      {{{"rendering_noise", "no"}}, "body.rendering_noise"},
      {{{"noise_neighbours", 0}}, "body.noise_neighbours"},
      {{{"noise_neighbours", -1}}, "body.noise_neighbours"},
      {{{"noise_neighbours", 2.5}}, "body.noise_neighbours"},
      {{{"noise_neighbours", 8.5}}, "body.noise_neighbours"},
      {{{"noise_neighbours", 0.0}}, "body.noise_neighbours"},
      {{{"noise_neighbours", -8.0}}, "body.noise_neighbours"},
      {{{"noise_neighbours", 1e300}}, "body.noise_neighbours"},
      {{{"noise_neighbours", 4294967304.0}}, "body.noise_neighbours"},  // 2^32 + 8: 8 if wrapped into an int
      {{{"noise_neighbours", true}}, "body.noise_neighbours"},
      {{{"noise_neighbours", "8"}}, "body.noise_neighbours"},
      {{{"noise_pooling", "sum"}}, "body.noise_pooling"},
      // Said to be made without the rendering's noise, while its budgets carry it.
      {{{"rendering_noise", false}, {"result", result4}}, "rendering_noise is false"},
  };
  for (const auto& [patch, names] : bad_bodies) {
    json b = body;
    b.erase("noise_neighbours");
    b.update(patch);
    try {
      api.post("/v1/verifications", b);
      ADD_FAILURE() << "stored: " << patch.dump();
    } catch (const client::ApiError& e) {
      EXPECT_EQ(e.problem().status, 400) << patch.dump();
      EXPECT_NE(e.problem().detail.find(names), std::string::npos) << e.problem().detail;
    }
  }
}

// One spot's cell textured among noisy neighbours: the screen judges that region on its own spread (the truth: the
// planted cell, whose band is then the widest of its kind), and the plain-text summary names the regions left out as
// the JSON lists them; a faithful rendering's summary names none. The test's floor is piecewise constant, so regions
// that straddle a cell's edge are left out too (an edge is not noise); the bound is on the planted one.
void a_textured_spot_is_named_in_the_plain_text_summary() {
  const json& spot = (*truth_)["spots"][0];
  const std::pair cell{spot["row"].get<int>(), spot["col"].get<int>()};
  verify::write_openexr(true_floor(*truth_, 1.0, cell), dir_->path() / "textured.exr");
  const std::string planted = "r" + std::to_string(cell.first) + "c" + std::to_string(cell.second);
  auto args = verify_args("textured.exr");
  const auto r = cli(args);
  ASSERT_TRUE(r.exit_code == 0 || r.exit_code == 4) << r.err;
  const json result = json::parse(r.out);
  args.erase(std::find(args.begin(), args.end(), "--json"));
  const auto text = cli(args);
  ASSERT_TRUE(text.exit_code == 0 || text.exit_code == 4) << text.err;
  for (const auto& [kind, k] : result["summary"]["kinds"].items()) {
    const json& own = k["rendering_noise_left_out"];
    EXPECT_NE(std::find(own.begin(), own.end(), planted), own.end()) << kind << ": " << own.dump();
    std::string widest;
    double widest_noise = -1;
    for (const auto& c : result["comparisons"]) {
      if (c["kind"] != kind) continue;
      const double n = c["budget"].value("rendering noise", 0.0);
      if (n > widest_noise) widest_noise = n, widest = c["where"];
    }
    EXPECT_EQ(widest, planted) << kind;
    std::string line = "    the rendering's noise judged on its own at:";
    for (std::size_t i = 0; i < std::min<std::size_t>(own.size(), 8); ++i) line += " " + own[i].get<std::string>();
    EXPECT_NE(text.out.find(line), std::string::npos) << line << "\n"
                                                      << text.out;
  }
  auto faithful = verify_args("faithful.exr");
  faithful.erase(std::find(faithful.begin(), faithful.end(), "--json"));
  const auto plain = cli(faithful);
  EXPECT_EQ(plain.out.find("judged on its own"), std::string::npos) << plain.out;
}

}  // namespace

// One daemon and one pair of campaigns for every check (ctest runs each TEST in its own process): the campaigns are
// the test's cost.
TEST(VerifyCli, EndToEndAgainstTheSimulatedLab) {
  try {
    Lab::start();
  } catch (const std::exception& e) {
    Lab::stop();
    FAIL() << "setting up the lab: " << e.what();
  }
  if (HasFatalFailure()) {
    Lab::stop();
    return;
  }
  {
    SCOPED_TRACE("the true floor");
    the_true_floor_agrees_at_95_percent_of_the_spots();
  }
  {
    SCOPED_TRACE("a lamp 10 % too bright");
    a_lamp_ten_percent_too_bright_differs_and_exits_4();
  }
  {
    SCOPED_TRACE("bad inputs");
    bad_inputs_are_typed_errors_with_their_exit_codes();
  }
  {
    SCOPED_TRACE("--store");
    store_makes_a_run_readable_through_the_api();
  }
  {
    SCOPED_TRACE("the rendering's noise options");
    rendering_noise_options_are_recorded_and_checked();
  }
  {
    SCOPED_TRACE("a textured spot in the plain-text summary");
    a_textured_spot_is_named_in_the_plain_text_summary();
  }
  Lab::stop();
}
