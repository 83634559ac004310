// Exports of real runs on the simulated lab (GET /v1/runs/{id}/export, `colorlab export`), judged by
// independent readers: ArgyllCMS builds an ICC profile from a characterization's .ti3 (colprof), checks it
// (profcheck) and recomputes the colours from its spectra (spec2cie); the project's CSV reader gives back
// every stored value; the JSON export is the measurements API's answer.
#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <regex>

#include <strings.h>

#include <gtest/gtest.h>

#include "colorlab/analysis/cgats.hpp"
#include "colorlab/analysis/csv.hpp"
#include "colorlab/client/runs.hpp"
#include "colorlab/testing/process.hpp"
#include "resume_support.hpp"

using namespace colorlab;
using namespace colorlab::testing;
using nlohmann::json;

namespace {

constexpr std::uint64_t kSeed = 5;
// Half the 20D's sensor renders quickly; the chart still spans hundreds of pixels.
constexpr const char* kLabToml = "[genicam]\nenabled = false\n[dslr]\nsize = [1752, 1168]\n";

// One daemon, three runs, shared by the suite: a chart-read, a raw-only characterization against it, and a
// luminance-spot run (no patches).
struct Lab {
  TempDir dir;
  std::unique_ptr<DaemonProcess> daemon;
  std::unique_ptr<client::ApiClient> api;
  json chart_read, characterization, spot;

  Lab() {
    auto config = write_daemon_config(dir.path(), 500, kSeed);
    std::ofstream(dir / "lab.toml") << kLabToml;
    daemon = std::make_unique<DaemonProcess>(dir / "state", config);
    api = std::make_unique<client::ApiClient>(api_for(*daemon));
    chart_read = run_to_end(*api, "chart-read", json::object());
    characterization = run_to_end(*api, "characterize-camera",
                                  {
                                      {"reference_run", chart_read["id"]},
                                      {"frames", 1},
                                      {"formats", {"raw"}},
                                      {"prior_exclude", {"Canon_20D"}},
                                  },
                                  std::chrono::seconds(300));
    spot = run_to_end(*api, "luminance-spot", {{"readings", 3}});
  }

  client::RawResponse get(const std::string& target, const std::map<std::string, std::string>& headers = {}) const {
    return api->request("GET", target, {}, headers);
  }
  client::RawResponse export_of(const json& run, const std::string& query) const {
    return get("/v1/runs/" + run["id"].get<std::string>() + "/export?" + query);
  }
};

Lab* lab = nullptr;

class Exports : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!lab) lab = new Lab();
  }
  static void TearDownTestSuite() {
    delete lab;
    lab = nullptr;
  }
};

std::string header(const client::RawResponse& r, const std::string& name) {
  for (const auto& [k, v] : r.headers)
    if (strcasecmp(k.c_str(), name.c_str()) == 0) return v;
  return {};
}

std::filesystem::path save(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

// run_command execs a path, not a name looked up on PATH.
std::string tool(const std::string& name) {
  std::string path = shell_output("command -v " + name);
  while (!path.empty() && (path.back() == '\n' || path.back() == ' ')) path.pop_back();
  return path.empty() ? name : path;
}

#define REQUIRE_TOOL_CURL() \
  if (!on_path("curl")) GTEST_SKIP() << "curl is not installed: scripts/setup.sh installs it"

#define REQUIRE_ARGYLL(tool) \
  if (!on_path(tool)) GTEST_SKIP() << tool << " (ArgyllCMS) is not installed: scripts/setup.sh installs argyll"

// spec2cie on `ti3`: its XYZ of each patch's spectrum against the XYZ the file carries. colorlab's
// integrator and Argyll's agree within 0.07 on 10 nm reflectances under D50, 2° (analysis_spec2cie_test).
void expect_spec2cie_agrees(const std::filesystem::path& ti3, std::size_t patches) {
  const auto out = ti3.parent_path() / (ti3.stem().string() + "-spec2cie.ti3");
  auto r = run_command({tool("spec2cie"), "-i", "D50", "-o", "1931_2", ti3.string(), out.string()});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const auto in = analysis::read_cgats(ti3), back = analysis::read_cgats(out);
  ASSERT_EQ(back.rows.size(), patches);
  ASSERT_EQ(in.rows.size(), patches);
  double worst = 0;
  for (std::size_t i = 0; i < patches; ++i) {
    ASSERT_EQ(back.rows[i][*back.field_index("SAMPLE_ID")], in.rows[i][*in.field_index("SAMPLE_ID")]);
    for (const char* f : {"XYZ_X", "XYZ_Y", "XYZ_Z"}) worst = std::max(worst, std::abs(back.number(i, f) - in.number(i, f)));
  }
  std::cout << "[export] spec2cie " << ti3.filename().string() << ": max |dXYZ| " << worst << "\n";
  EXPECT_LE(worst, 0.07);
}

TEST_F(Exports, CharacterizationTi3MakesAnArgyllProfileThatProfcheckAccepts) {
  REQUIRE_ARGYLL("colprof");
  ASSERT_EQ(lab->characterization["status"], "finished_ok");
  auto r = lab->export_of(lab->characterization, "format=ti3");
  ASSERT_EQ(r.status, 200) << r.body;
  EXPECT_EQ(r.content_type.rfind("text/x-cgats", 0), 0u) << r.content_type;
  const std::string id = lab->characterization["id"];
  EXPECT_EQ(header(r, "Content-Disposition"), "attachment; filename=\"characterize-camera-" + id + "-raw.ti3\"");
  const auto ti3 = save(lab->dir / "camera.ti3", r.body);
  const auto table = analysis::read_cgats(ti3);
  EXPECT_EQ(table.file_type, "CTI3");
  EXPECT_EQ(table.keyword("DEVICE_CLASS").value_or(""), "INPUT");
  EXPECT_EQ(table.keyword("COLORLAB_REFERENCE_RUN").value_or(""), lab->chart_read["id"]);
  ASSERT_EQ(table.rows.size(), 140u);

  // Every row pairs the run's camera values with the chart-read's reading of the same patch.
  std::map<std::string, json> camera, reference;
  for (const auto& m : lab->characterization["measurements"])
    if (m["quantity"] == "camera_rgb") camera[m["data"]["id"]] = m["data"]["rgb"];
  for (const auto& m : lab->chart_read["measurements"]) reference[m["data"]["id"]] = m["data"];
  const double full = std::stod(table.keyword("COLORLAB_RGB_FULL_SCALE").value());
  for (std::size_t i = 0; i < table.rows.size(); ++i) {
    const std::string pid = table.rows[i][*table.field_index("SAMPLE_ID")];
    ASSERT_TRUE(camera.count(pid) && reference.count(pid)) << pid;
    for (int c = 0; c < 3; ++c) {
      const char* rgb[] = {"RGB_R", "RGB_G", "RGB_B"};
      const char* xyz[] = {"XYZ_X", "XYZ_Y", "XYZ_Z"};
      // Six decimals on 0–100.
      EXPECT_NEAR(table.number(i, rgb[c]), std::clamp(100 * camera[pid][c].get<double>() / full, 0.0, 100.0), 1e-6) << pid;
      EXPECT_NEAR(table.number(i, xyz[c]), reference[pid]["XYZ"][c].get<double>(), 1e-6) << pid;
    }
  }

  // colprof builds an input profile from it; profcheck reads it against that profile. A pairing error (a
  // patch's values beside another's colour, or channels out of scale) shows as tens of ΔE; a camera whose
  // raw is linear in the light fits its chart within a few.
  const auto base = lab->dir / "camera";
  auto made = run_command({tool("colprof"), "-v", "-qm", "-ax", base.string()}, std::chrono::seconds(300));
  ASSERT_EQ(made.exit_code, 0) << made.out << made.err;
  ASSERT_TRUE(std::filesystem::exists(base.string() + ".icc"));
  auto check = run_command({tool("profcheck"), ti3.string(), base.string() + ".icc"}, std::chrono::seconds(120));
  ASSERT_EQ(check.exit_code, 0) << check.out << check.err;
  std::smatch m;
  const std::string text = check.out + check.err;
  ASSERT_TRUE(std::regex_search(text, m, std::regex(R"(max\. = ([0-9.]+), avg\. = ([0-9.]+))"))) << text;
  const double peak = std::stod(m[1]), avg = std::stod(m[2]);
  std::cout << "[export] profcheck " << ti3.filename().string() << ": avg " << avg << ", max " << peak << " ΔE*ab\n";
  EXPECT_GT(avg, 0);
  EXPECT_LT(avg, 10);

  // The reference's spectra travel with it: spec2cie recomputes each patch's XYZ from them.
  REQUIRE_ARGYLL("spec2cie");
  expect_spec2cie_agrees(ti3, 140);
}

TEST_F(Exports, ChartReadTi3CarriesEachPatchsSpectrumThatSpec2cieReads) {
  REQUIRE_ARGYLL("spec2cie");
  auto r = lab->export_of(lab->chart_read, "format=ti3");
  ASSERT_EQ(r.status, 200) << r.body;
  const std::string id = lab->chart_read["id"];
  EXPECT_EQ(header(r, "Content-Disposition"), "attachment; filename=\"chart-read-" + id + ".ti3\"");
  const auto ti3 = save(lab->dir / "chart.ti3", r.body);
  const auto table = analysis::read_cgats(ti3);
  EXPECT_EQ(table.keyword("DEVICE_CLASS").value_or(""), "OUTPUT");
  EXPECT_EQ(table.keyword("SPECTRAL_BANDS").value_or(""), "36");
  ASSERT_EQ(table.rows.size(), lab->chart_read["measurements"].size());
  expect_spec2cie_agrees(ti3, table.rows.size());
}

TEST_F(Exports, CsvReadsBackEveryStoredValue) {
  for (const json* run : {&lab->chart_read, &lab->spot}) {
    auto r = lab->export_of(*run, "format=csv");
    ASSERT_EQ(r.status, 200) << r.body;
    EXPECT_EQ(r.content_type.rfind("text/csv", 0), 0u);
    const auto t = analysis::parse_csv(r.body, "export.csv");
    const json stored = client::fetch_measurements(*lab->api, (*run)["id"]);
    ASSERT_EQ(t.rows.size(), stored.size());
    for (std::size_t i = 0; i < t.rows.size(); ++i) {
      const json& m = stored[i];
      EXPECT_EQ(t.rows[i][t.require_column("seq")], std::to_string(m["seq"].get<std::int64_t>()));
      for (const char* text : {"step", "instrument_id", "quantity", "unit", "measured_at"})
        EXPECT_EQ(t.rows[i][t.require_column(text)], m[text].get<std::string>()) << text;
      EXPECT_EQ(t.rows[i][t.require_column("simulated")], m["simulated"].get<bool>() ? "true" : "false");
      // Exactly the stored double, not a rounding of it.
      EXPECT_EQ(t.number(i, t.require_column("value")), m["value"].get<double>()) << m["step"];
      EXPECT_EQ(json::parse(t.rows[i][t.require_column("data")]), m["data"]) << m["step"];
    }
  }
}

TEST_F(Exports, JsonIsTheRunAndTheMeasurementsApisItems) {
  auto r = lab->export_of(lab->chart_read, "format=json");
  ASSERT_EQ(r.status, 200) << r.body;
  const json doc = json::parse(r.body);
  const std::string id = lab->chart_read["id"];
  EXPECT_EQ(doc["measurements"], client::fetch_measurements(*lab->api, id));
  json run = lab->api->get("/v1/runs/" + id);
  for (const char* key : {"id", "campaign", "params", "status", "summary", "created_at", "finished_at"}) EXPECT_EQ(doc["run"][key], run[key]) << key;
  EXPECT_EQ(header(r, "Content-Disposition"), "attachment; filename=\"chart-read-" + id + ".json\"");
  // Without format=, the Accept header chooses.
  auto csv = lab->get("/v1/runs/" + id + "/export", {{"Accept", "text/csv"}});
  EXPECT_EQ(csv.status, 200);
  EXPECT_EQ(csv.content_type.rfind("text/csv", 0), 0u);
  EXPECT_EQ(csv.body, lab->export_of(lab->chart_read, "format=csv").body);
}

TEST_F(Exports, RefusalsAreProblems) {
  auto problem = [](const client::RawResponse& r) {
    EXPECT_EQ(r.content_type, "application/problem+json");
    return json::parse(r.body);
  };
  auto bad = lab->export_of(lab->chart_read, "format=xlsx");
  EXPECT_EQ(bad.status, 400);
  EXPECT_NE(problem(bad)["detail"].get<std::string>().find("ti3, csv or json"), std::string::npos);
  auto unknown = lab->get("/v1/runs/01900000-0000-7000-8000-00000000dead/export?format=csv");
  EXPECT_EQ(unknown.status, 404);
  EXPECT_EQ(problem(unknown)["code"], "not_found");
  // A luminance run has no patches to pair with device values: a .ti3 is refused, saying why.
  auto spot = lab->export_of(lab->spot, "format=ti3");
  EXPECT_EQ(spot.status, 422);
  const json p = problem(spot);
  EXPECT_EQ(p["code"], "not-exportable");
  EXPECT_NE(p["detail"].get<std::string>().find("no patch readings"), std::string::npos) << p.dump();
  EXPECT_EQ(lab->export_of(lab->spot, "format=json").status, 200);
  // A format the characterization did not photograph.
  auto jpeg = lab->export_of(lab->characterization, "format=ti3&camera_format=jpeg");
  EXPECT_EQ(jpeg.status, 400);
  EXPECT_EQ(lab->get("/v1/runs/" + lab->spot["id"].get<std::string>() + "/export", {{"Accept", "image/png"}}).status, 400);
  EXPECT_EQ(lab->api->request("POST", "/v1/runs/" + lab->spot["id"].get<std::string>() + "/export").status, 405);
}

TEST_F(Exports, CliWritesTheApisBytesToStdoutOrAFile) {
  const std::string url = lab->daemon->url(), id = lab->chart_read["id"];
  auto out = run_command({bin_path("colorlab"), "--url", url, "export", id, "--format", "csv"});
  ASSERT_EQ(out.exit_code, 0) << out.err;
  EXPECT_EQ(out.out, lab->export_of(lab->chart_read, "format=csv").body);
  // A directory takes the daemon's file name.
  const auto dir = lab->dir / "exports";
  std::filesystem::create_directories(dir);
  auto file = run_command({bin_path("colorlab"), "--url", url, "export", id, "--format", "ti3", "-o", dir.string()});
  ASSERT_EQ(file.exit_code, 0) << file.err;
  const auto path = dir / ("chart-read-" + id + ".ti3");
  ASSERT_TRUE(std::filesystem::exists(path)) << file.out;
  std::ifstream f(path, std::ios::binary);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(f), {}), lab->export_of(lab->chart_read, "format=ti3").body);
  // Refusals exit 2 with the server's detail, as every API command does.
  auto refused = run_command({bin_path("colorlab"), "--url", url, "export", lab->spot["id"].get<std::string>(), "--format", "ti3"});
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("no patch readings"), std::string::npos) << refused.err;
  auto help = run_command({bin_path("colorlab"), "export", "--help"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("--format"), std::string::npos);
}

}  // namespace

// HEAD is GET without the body on every route that answers GET (RFC 9110 §9.3.2): here an export and
// the run list, through curl, an independent client.
TEST_F(Exports, HeadAnswersAsGetWithoutTheBody) {
  REQUIRE_TOOL_CURL();
  const std::string id = lab->chart_read["id"];
  const auto get = lab->export_of(lab->chart_read, "format=csv");
  for (const std::string& target : {"/v1/runs/" + id + "/export?format=csv", std::string("/v1/runs")}) {
    auto head = run_command({tool("curl"), "-sS", "-I", lab->daemon->url() + target});
    ASSERT_EQ(head.exit_code, 0) << head.err;
    EXPECT_EQ(head.out.rfind("HTTP/1.1 200", 0), 0u) << target << "\n"
                                                     << head.out;
    // curl -I prints the headers alone: a body would follow a blank line.
    EXPECT_EQ(head.out.find("\r\n\r\n") + 4, head.out.size()) << target;
  }
  auto head = run_command({tool("curl"), "-sS", "-I", lab->daemon->url() + "/v1/runs/" + id + "/export?format=csv"});
  EXPECT_NE(head.out.find("text/csv"), std::string::npos) << head.out;
  EXPECT_NE(head.out.find("ontent-Length: " + std::to_string(get.body.size())), std::string::npos) << head.out;
}
