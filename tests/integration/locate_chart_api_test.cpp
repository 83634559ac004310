// The chart located in a photograph the daemon keeps (issue 14: the operator's corners over the API and the CLI):
// POST /v1/blobs/{sha256}/locate-chart on the simulated DSLR's frames, the chart at its seeded pose — patch centres
// within 2 px of the simulator's geometry of that very shot and raw values equal to its noiseless truth within the
// noise it injects; the operator's corners; a photograph with no chart refused with a typed code and a hint; unknown
// blobs, bad JSON and bad corners; the read scope; `colorlab locate-chart --blob` printing what
// `colorlab analyze locate-chart` prints for the same mosaic; characterize-camera refusing a dark photograph with
// the kept blob and the command in its hint, and taking the operator's corners on the next run.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <set>

#include "colorlab/client/api_client.hpp"
#include "colorlab/drivers/camera/raw_decoder.hpp"
#include "colorlab/sim/control_channel.hpp"
#include "resume_support.hpp"

using namespace colorlab;
using namespace colorlab::testing;
using nlohmann::json;

namespace {

constexpr double kCentreBound = 2.0;  // px, the goal
constexpr const char* kLabToml = "[genicam]\nenabled = false\n[dslr]\nsize = [1752, 1168]\n";

std::pair<int, json> call(const client::ApiClient& api, const std::string& method, const std::string& target,
                          const std::string& body, const std::map<std::string, std::string>& headers = {{"Content-Type", "application/json"}}) {
  auto r = api.request(method, target, body, headers);
  return {r.status, json::parse(r.body, nullptr, false)};
}

std::pair<int, json> locate(const client::ApiClient& api, const std::string& sha, const json& body) {
  return call(api, "POST", "/v1/blobs/" + sha + "/locate-chart", body.dump());
}

// The daemon, one frame-average series under D65 (its DNG and the average kept) and one in the dark, shared by the
// tests below: each series takes seconds of rendering on a shared machine.
class LocateChartApi : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir();
    auto config = write_daemon_config(dir_->path(), 500, 5);
    std::ofstream(*dir_ / "lab.toml") << kLabToml;
    daemon_ = new DaemonProcess(*dir_ / "state", config);
    auto api = api_for(*daemon_);
    // The SG's reference read: its L2, L3, M2, M3 are as light as the surround and show no edges of their own.
    reference_ = new std::string(run_to_end(api, "chart-read", json::object())["id"].get<std::string>());
    control({{"cmd", "lamp"}, {"lamp", "D65"}, {"on", true}});
    control({{"cmd", "dimmer"}, {"percent", 100}});
    lit_ = new json(kept(api, run_to_end(api, "frame-average", {{"frames", 2}})));
    control({{"cmd", "lamp"}, {"lamp", "D65"}, {"on", false}});
    dark_ = new json(kept(api, run_to_end(api, "frame-average", {{"frames", 2}})));
    control({{"cmd", "lamp"}, {"lamp", "D65"}, {"on", true}});
  }
  static void TearDownTestSuite() {
    delete lit_;
    delete dark_;
    delete reference_;
    delete daemon_;
    delete dir_;
  }

  static json control(const json& command) {
    json endpoint = json::parse(std::ifstream(daemon_->state_dir() / "colorlabd.endpoint"));
    json r = sim::send_control_command(endpoint.at("simulator_control").get<std::string>(), command);
    EXPECT_TRUE(r.value("ok", false)) << r.dump();
    return r;
  }
  // kind → blob item of the run
  static json kept(const client::ApiClient& api, const json& run) {
    json by_kind = json::object();
    const json listed = api.get("/v1/runs/" + run["id"].get<std::string>() + "/blobs");
    for (const auto& b : listed["items"]) by_kind[b["kind"].get<std::string>()] = b;
    EXPECT_TRUE(by_kind.contains("raw") && by_kind.contains("average")) << listed.dump(2);
    return by_kind;
  }
  static std::string sha(const json& kinds, const char* kind) { return kinds[kind]["sha256"].get<std::string>(); }
  // The simulator's truth of the shot a kept DNG came from.
  static json truth_of(const json& raw_blob) {
    return control({{"cmd", "camera_truth"}, {"instrument", "dslr"}, {"file", raw_blob["meta"]["file_name"]}});
  }
  static client::ApiClient api() { return api_for(*daemon_); }
  static std::vector<std::string> cli(std::vector<std::string> args) {
    args.insert(args.begin(), {bin_path("colorlab"), "--socket", daemon_->unix_socket()});
    return args;
  }

  // Every patch centre within kCentreBound of the centre of the simulator's patch region (the largest axis-aligned
  // rectangle centred on the patch, so its centre is the patch's to half a pixel of rounding).
  static void expect_centres(const json& located, const json& truth, const std::string& what) {
    ASSERT_EQ(located["patches"].size(), 140u) << what;
    double worst = 0;
    for (std::size_t k = 0; k < 140; ++k) {
      const json& p = located["patches"][k];
      const json& r = truth["patches"][k]["region"];
      const double tx = r[0].get<double>() + (r[2].get<double>() - 1) / 2, ty = r[1].get<double>() + (r[3].get<double>() - 1) / 2;
      const double d = std::hypot(p["x"].get<double>() - tx, p["y"].get<double>() - ty);
      worst = std::max(worst, d);
      EXPECT_LE(d, kCentreBound) << what << " patch " << p["id"];
    }
    std::printf("[ %s ] worst centre error %.2f px\n", what.c_str(), worst);
  }

  static TempDir* dir_;
  static DaemonProcess* daemon_;
  static json* lit_;
  static json* dark_;
  static std::string* reference_;
};

TempDir* LocateChartApi::dir_ = nullptr;
DaemonProcess* LocateChartApi::daemon_ = nullptr;
json* LocateChartApi::lit_ = nullptr;
json* LocateChartApi::dark_ = nullptr;
std::string* LocateChartApi::reference_ = nullptr;

TEST_F(LocateChartApi, FindsEveryPatchOfTheKeptRawWhereTheSimulatorPutItWithItsValue) {
  const json& raw = (*lit_)["raw"];
  auto [status, located] = locate(api(), sha(*lit_, "raw"), {{"chart", "sg"}, {"reference_run", *reference_}});
  ASSERT_EQ(status, 200) << located.dump(2);
  EXPECT_EQ(located["chart"][0]["chart"], "sg");
  EXPECT_EQ(located["chart"][0]["from_corners"], "no");
  EXPECT_EQ(located["chart"][0]["check_passed"], "yes") << located["chart"][0].dump();
  EXPECT_EQ(located["corners"].size(), 4u);
  EXPECT_EQ(located["blob"]["media_type"], "image/x-adobe-dng");
  EXPECT_TRUE(located["blob"]["mosaic"].get<bool>());
  const json truth = truth_of(raw);
  expect_centres(located, truth, "raw DNG");
  // Raw counts per CFA colour against the noiseless mean of that shot: within 5σ of the sampled mean (σ: every
  // per-pixel spread the simulator injects there; the fewest pixels of a colour are a quarter of those used) and half
  // a count. Dusty patches are left out of the truth.
  std::set<int> dusty;
  for (const auto& d : truth["dust_patches"]) dusty.insert(d.get<int>());
  for (std::size_t k = 0; k < 140; ++k) {
    if (dusty.count(static_cast<int>(k))) continue;
    const json& p = located["patches"][k];
    const double n = p["used"].get<double>() / 4;
    for (std::size_t c = 0; c < 3; ++c) {
      const double want = truth["patches"][k]["mean"][c].get<double>();
      const double bound = 5 * truth["patches"][k]["pixel_sigma"][c].get<double>() / std::sqrt(n) + 0.5;
      EXPECT_NEAR(p[std::string(1, "RGB"[c])].get<double>(), want, bound) << "patch " << p["id"] << " channel " << c;
    }
  }
}

TEST_F(LocateChartApi, FindsThePatchesInTheAveragedFrameToo) {
  auto [status, located] = locate(api(), sha(*lit_, "average"), {{"chart", "sg"}, {"reference_run", *reference_}});
  ASSERT_EQ(status, 200) << located.dump(2);
  EXPECT_EQ(located["blob"]["media_type"], "application/x-colorlab-array");
  expect_centres(located, truth_of((*lit_)["raw"]), "average");
}

TEST_F(LocateChartApi, TakesTheOperatorsCornersAndRefusesThemInTheWrongOrder) {
  auto [status, automatic] = locate(api(), sha(*lit_, "raw"), {{"reference_run", *reference_}});
  ASSERT_EQ(status, 200) << automatic.dump(2);
  // Corners as a person clicks them: a few pixels off.
  json corners = json::array();
  const double dx[4] = {4, -3, 2, -4}, dy[4] = {-3, 4, -2, 3};
  for (std::size_t i = 0; i < 4; ++i)
    corners.push_back({automatic["corners"][i]["x"].get<double>() + dx[i], automatic["corners"][i]["y"].get<double>() + dy[i]});
  auto [given_status, given] =
      locate(api(), sha(*lit_, "raw"), {{"chart", "sg"}, {"corners", corners}, {"reference_run", *reference_}, {"sample_fraction", 0.5}});
  ASSERT_EQ(given_status, 200) << given.dump(2);
  EXPECT_EQ(given["chart"][0]["from_corners"], "yes");
  expect_centres(given, truth_of((*lit_)["raw"]), "operator corners");
  // Starting from another corner says the chart is turned: its own luminances disagree, and it is refused rather
  // than read with every patch's id wrong.
  json turned = json::array({corners[2], corners[3], corners[0], corners[1]});
  auto [turned_status, refused] = locate(api(), sha(*lit_, "raw"), {{"chart", "sg"}, {"corners", turned}, {"reference_run", *reference_}});
  EXPECT_EQ(turned_status, 422) << refused.dump(2);
  EXPECT_EQ(refused["code"], "chart-needs-corners") << refused.dump(2);
}

TEST_F(LocateChartApi, WithoutItsReferenceTheSgsEdgelessPatchesReadAsACoverAndAreRefused) {
  auto [status, problem] = locate(api(), sha(*lit_, "raw"), {{"chart", "sg"}});
  EXPECT_EQ(status, 422) << problem.dump(2);
  EXPECT_EQ(problem["code"], "chart-needs-corners") << problem.dump(2);
  EXPECT_EQ(problem["locator_error"], "needs_operator");
  EXPECT_NE(problem["detail"].get<std::string>().find("L2"), std::string::npos) << problem["detail"];
  // A reference of another chart is a bad request, an unknown one not found.
  EXPECT_EQ(locate(api(), sha(*lit_, "raw"), {{"chart", "cc24"}, {"reference_run", *reference_}}).first, 400);
  EXPECT_EQ(locate(api(), sha(*lit_, "raw"), {{"reference_run", "01a20b14-0000-7000-8000-000000000000"}}).first, 404);
}

TEST_F(LocateChartApi, APhotographWithNoChartIsRefusedWithATypedCodeAndAHint) {
  auto [status, problem] = locate(api(), sha(*dark_, "raw"), {{"chart", "sg"}, {"reference_run", *reference_}});
  EXPECT_EQ(status, 422) << problem.dump(2);
  EXPECT_TRUE(problem["code"] == "chart-not-found" || problem["code"] == "chart-needs-corners") << problem.dump(2);
  EXPECT_EQ(problem["blob"], sha(*dark_, "raw"));
  EXPECT_NE(problem["hint"].get<std::string>().find("\"corners\""), std::string::npos) << problem["hint"];
  EXPECT_EQ(problem["status"], 422);
  // The CLI: exit 2 (the API refused), the detail and the hint on stderr.
  auto r = run_command(cli({"locate-chart", "--blob", sha(*dark_, "raw"), "--reference-run", *reference_}));
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("422"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("hint:"), std::string::npos) << r.err;
}

TEST_F(LocateChartApi, UnknownBlobsBadJsonAndBadCornersAreRefused) {
  auto a = api();
  const std::string lit = sha(*lit_, "raw");
  auto [unknown, p1] = locate(a, std::string(64, '0'), json::object());
  EXPECT_EQ(unknown, 404) << p1.dump();
  EXPECT_EQ(p1["code"], "not_found");
  EXPECT_EQ(locate(a, "not-a-hash", json::object()).first, 404);
  auto [bad_json, p2] = call(a, "POST", "/v1/blobs/" + lit + "/locate-chart", "{\"chart\": ");
  EXPECT_EQ(bad_json, 400);
  EXPECT_EQ(p2["code"], "bad-json");
  auto [three, p3] = locate(a, lit, {{"corners", {{1, 2}, {3, 4}, {5, 6}}}});
  EXPECT_EQ(three, 400);
  EXPECT_EQ(p3["code"], "bad-request");
  auto [outside, p4] = locate(a, lit, {{"corners", {{10, 10}, {5000, 10}, {5000, 900}, {10, 900}}}});
  EXPECT_EQ(outside, 400) << p4.dump();
  EXPECT_EQ(p4["code"], "bad-corners");
  auto [crossed, p5] = locate(a, lit, {{"corners", {{100, 100}, {900, 900}, {900, 100}, {100, 900}}}});
  EXPECT_EQ(crossed, 400) << p5.dump();
  EXPECT_EQ(p5["code"], "bad-corners");
  EXPECT_EQ(locate(a, lit, {{"chart", "it8"}}).first, 400);
  EXPECT_EQ(locate(a, lit, {{"shrink", 0.5}}).first, 400);  // unknown members are typos, not ignored
  EXPECT_EQ(locate(a, lit, {{"sample_fraction", 0}}).first, 400);
  EXPECT_EQ(call(a, "POST", "/v1/blobs/" + lit + "/locate-chart", "{}", {{"Content-Type", "text/plain"}}).first, 415);
  auto [get, p6] = call(a, "GET", "/v1/blobs/" + lit + "/locate-chart", "");
  EXPECT_EQ(get, 405);
  // The CLI checks the corners before asking: a local error, exit 1.
  auto r = run_command(cli({"locate-chart", "--blob", lit, "--corners", "1,2,3"}));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("8 numbers"), std::string::npos) << r.err;
}

TEST_F(LocateChartApi, LocatingNeedsOnlyTheReadScope) {
  // Loopback TCP without a key has the read scope: locating is allowed, a control route is not.
  client::ApiClient open(client::Endpoint::from_url(daemon_->url()));
  auto [status, located] = locate(open, sha(*lit_, "raw"), {{"reference_run", *reference_}});
  EXPECT_EQ(status, 200) << located.dump(2);
  auto [control_status, problem] = call(open, "POST", "/v1/queue/start", "{}");
  EXPECT_EQ(control_status, 401);
  EXPECT_EQ(problem["required_scope"], "control");
}

TEST_F(LocateChartApi, TheCliPrintsWhatAnalyzeLocateChartPrintsForTheSameMosaic) {
  // The kept DNG decoded here (LibRaw, as dcraw -D -4 would) into a 16-bit PGM for the offline tool.
  const auto dng = *dir_ / "frame.dng";
  {
    auto r = api().request("GET", "/v1/blobs/" + sha(*lit_, "raw"));
    ASSERT_EQ(r.status, 200);
    std::ofstream(dng, std::ios::binary) << r.body;
  }
  auto image = drivers::camera::RawDecoder::for_this_thread().decode_file(dng);
  const auto pgm = *dir_ / "mosaic.pgm";
  {
    std::ofstream out(pgm, std::ios::binary);
    out << "P5\n"
        << image.width << " " << image.height << "\n65535\n";
    for (std::size_t y = 0; y < image.height; ++y)
      for (auto v : image.row(y)) out.put(static_cast<char>(v >> 8)).put(static_cast<char>(v & 0xff));
  }
  ASSERT_EQ(image.cfa.name(), "RGGB");
  // The offline tool takes no reference: both are given the same corners (the daemon's own, to a pixel).
  auto [status, automatic] = locate(api(), sha(*lit_, "raw"), {{"reference_run", *reference_}});
  ASSERT_EQ(status, 200) << automatic.dump(2);
  std::string corners;
  for (const auto& c : automatic["corners"])
    corners += (corners.empty() ? "" : ",") + std::to_string(std::lround(c["x"].get<double>())) + "," + std::to_string(std::lround(c["y"].get<double>()));
  auto offline = run_command({bin_path("colorlab"), "analyze", "locate-chart", pgm.string(), "--chart", "sg", "--cfa", "RGGB",
                              "--black", std::to_string(image.black_level[0]), "--bits", "12", "--corners", corners,
                              "--min-confidence", "0", "--json"});
  ASSERT_EQ(offline.exit_code, 0) << offline.err;
  auto daemon = run_command(cli({"locate-chart", "--blob", sha(*lit_, "raw"), "--chart", "sg", "--corners", corners,
                                 "--min-confidence", "0", "--json"}));
  ASSERT_EQ(daemon.exit_code, 0) << daemon.err;
  const json a = json::parse(offline.out), b = json::parse(daemon.out);
  for (const char* table : {"chart", "corners", "patches"}) {
    ASSERT_EQ(a[table].size(), b[table].size()) << table;
    for (std::size_t i = 0; i < a[table].size(); ++i) {
      const json& x = a[table][i];
      const json& y = b[table][i];
      for (const auto& [key, value] : x.items()) {
        ASSERT_TRUE(y.contains(key)) << table << "[" << i << "]." << key;
        if (value.is_number())
          EXPECT_NEAR(value.get<double>(), y[key].get<double>(), 1e-9 * std::max(1.0, std::abs(value.get<double>()))) << table << "[" << i << "]." << key;
        else
          EXPECT_EQ(value, y[key]) << table << "[" << i << "]." << key;
      }
      EXPECT_EQ(x.size(), y.size()) << table << "[" << i << "]";
    }
  }
  // Without --json: a summary and the patches, one line each.
  auto human = run_command(cli({"locate-chart", "--blob", sha(*lit_, "raw"), "--reference-run", *reference_}));
  ASSERT_EQ(human.exit_code, 0) << human.err;
  EXPECT_NE(human.out.find("confidence"), std::string::npos) << human.out;
  EXPECT_NE(human.out.find("\nA1,"), std::string::npos) << human.out;
}

TEST_F(LocateChartApi, CharacterizeCameraRefusesADarkPhotographWithTheBlobAndCommandThenTakesTheCorners) {
  auto a = api();
  const json params{
      {"reference_run", *reference_},
      {"frames", 2},
      {"formats", {"raw"}},
      {"lamp", ""},
      {"keep", json::array()},
      {"prior_exclude", {"Canon_20D"}},
  };
  // In the dark: refused. The run fails as needing a person, its hint naming the kept photograph and the commands.
  control({{"cmd", "lamp"}, {"lamp", "D65"}, {"on", false}});
  auto started = a.post("/v1/executions", {{"campaign", "characterize-camera"}, {"params", params}});
  const json failed = wait_terminal(a, started["id"], std::chrono::seconds(240));
  control({{"cmd", "lamp"}, {"lamp", "D65"}, {"on", true}});
  ASSERT_EQ(failed["status"], "finished_error") << failed.dump(2);
  const json error = failed["error"];
  EXPECT_EQ(error["code"], "needs_operator") << error.dump(2);
  const std::string hint = error["hint"];
  std::printf("[ refused ] %s\n  hint: %s\n", error["detail"].get<std::string>().c_str(), hint.c_str());
  EXPECT_NE(hint.find("colorlab locate-chart --blob "), std::string::npos) << hint;
  EXPECT_NE(hint.find("-p corners_raw=["), std::string::npos) << hint;
  // The photograph named is the one the run kept (the average the locator saw), though keep asked for none.
  const std::string run_id = failed["run_id"];
  const json blobs = a.get("/v1/runs/" + run_id + "/blobs")["items"];
  ASSERT_EQ(blobs.size(), 1u) << blobs.dump(2);
  EXPECT_EQ(blobs[0]["kind"], "average");
  EXPECT_NE(hint.find("colorlab locate-chart --blob " + blobs[0]["sha256"].get<std::string>()), std::string::npos) << hint;
  EXPECT_NE(hint.find("colorlab download " + blobs[0]["sha256"].get<std::string>() + " --preview"), std::string::npos) << hint;
  EXPECT_EQ(locate(a, blobs[0]["sha256"], {{"reference_run", *reference_}}).first, 422);

  // Lit, with the operator's corners (here: the corners found in the first series' raw, the chart has not moved).
  auto [status, automatic] = locate(a, sha(*lit_, "raw"), {{"reference_run", *reference_}});
  ASSERT_EQ(status, 200);
  json corners = json::array();
  for (const auto& c : automatic["corners"]) corners.push_back(std::round(c["x"].get<double>())), corners.push_back(std::round(c["y"].get<double>()));
  json with_corners = params;
  with_corners["corners_raw"] = corners;
  const json run = run_to_end(a, "characterize-camera", with_corners, std::chrono::seconds(240));
  ASSERT_EQ(run["status"], "finished_ok") << run["error"].dump(2);
  bool recorded = false;
  for (const auto& m : run["measurements"]) {
    if (m["step"] != "chart/raw") continue;
    recorded = true;
    EXPECT_TRUE(m["data"]["from_corners"].get<bool>()) << m.dump(2);
    EXPECT_GE(m["value"].get<double>(), 0.6) << m.dump(2);
  }
  EXPECT_TRUE(recorded);
}

}  // namespace
