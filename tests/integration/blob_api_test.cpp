// The image store end to end (issue 10) on the simulated DSLR: frame-average keeps its averaged
// frame as a float array, the first DNG as captured and a PNG preview; they are listed under the
// run; curl (an independent client) reads them byte-exact, in ranges and with ETags; the average
// read back with its dtype/shape/CFA headers gives exactly the noise the run recorded; a file
// without a row and a row without its file are reported by the next start, and nothing is
// deleted; kill -9 between a frame's file and its step leaves an orphan the next start reports.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <thread>

#include <sqlite3.h>

#include "resume_support.hpp"

using namespace colorlab::testing;
using nlohmann::json;

namespace {

void write_dslr_lab(const std::filesystem::path& dir) {
  std::ofstream(dir / "lab.toml") << "[genicam]\nenabled = false\n[dslr]\nsize = [640, 428]\n";
  std::ofstream(dir / "colorlabd.toml") << "[simulator]\nenabled = true\ntime_scale = 200\nseed = 3\nconfig = \"lab.toml\"\n";
}

std::string read_all(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

struct Fetched {
  int status = 0;
  std::map<std::string, std::string> headers;  // lower-case names
  std::string body;
};

// One request with curl: status, headers and body as received.
Fetched curl(const std::string& url, const std::vector<std::string>& args, const std::filesystem::path& dir) {
  const auto head = dir / "curl.headers", body = dir / "curl.body";
  // curl writes no file for an empty body: the last request's must not pass for this one's.
  std::filesystem::remove(head);
  std::filesystem::remove(body);
  static const std::string program = [] {
    std::string p = shell_output("command -v curl");
    while (!p.empty() && std::isspace(static_cast<unsigned char>(p.back()))) p.pop_back();
    return p;
  }();
  std::vector<std::string> argv = {program, "-s", "-D", head.string(), "-o", body.string()};
  argv.insert(argv.end(), args.begin(), args.end());
  argv.push_back(url);
  auto r = run_command(argv, std::chrono::seconds(30));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  Fetched f;
  std::istringstream in(read_all(head));
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.rfind("HTTP/", 0) == 0) {
      f.status = std::stoi(line.substr(line.find(' ') + 1, 3));
      f.headers.clear();
      continue;
    }
    auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string name = line.substr(0, colon);
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    f.headers[name] = line.substr(line.find_first_not_of(' ', colon + 1));
  }
  f.body = read_all(body);
  return f;
}

std::string sha256sum(const std::filesystem::path& p) { return shell_output("sha256sum '" + p.string() + "'").substr(0, 64); }

std::filesystem::path blob_file(const std::filesystem::path& state, const std::string& sha) {
  return state / "blobs" / sha.substr(0, 2) / sha.substr(2);
}

json wait_for_check(const colorlab::client::ApiClient& api) {
  json report;
  for (int i = 0; i < 600; ++i) {
    report = api.get("/v1/blobs/check");
    if (report.value("state", "") == "done" || report.value("state", "") == "failed") return report;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return report;
}

std::set<std::string> shas(const json& list) {
  std::set<std::string> out;
  for (const auto& e : list) out.insert(e["sha256"].get<std::string>());
  return out;
}

// The sample standard deviation of one CFA colour's samples in the region, as frame_statistics takes
// them (the first green only: the green on the region's first row parity) — recomputed here from
// the average the API served, independently of the daemon's code.
double region_stdev(const std::vector<float>& average, std::size_t width, const std::string& cfa, const json& region,
                    char colour) {
  const std::size_t x0 = region[0], y0 = region[1], w = region[2], h = region[3];
  std::vector<double> v;
  for (std::size_t y = y0; y < y0 + (h / 2) * 2; ++y) {
    for (std::size_t x = x0; x < x0 + (w / 2) * 2; ++x) {
      const char c = cfa[(y % 2) * 2 + (x % 2)];
      if (c != colour) continue;
      if (c == 'G' && (y % 2) != (y0 % 2)) continue;
      v.push_back(average[y * width + x]);
    }
  }
  double mean = 0;
  for (double x : v) mean += x;
  mean /= static_cast<double>(v.size());
  double ss = 0;
  for (double x : v) ss += (x - mean) * (x - mean);
  return std::sqrt(ss / static_cast<double>(v.size() - 1));
}

}  // namespace

TEST(BlobApi, FrameAverageKeepsItsFramesAndServesThemByteExact) {
  ASSERT_TRUE(on_path("curl"));
  TempDir dir;
  write_dslr_lab(dir.path());
  DaemonProcess daemon(dir / "state", dir / "colorlabd.toml", dir / "colorlabd.log");
  auto api = api_for(daemon);
  const json run = run_to_end(api, "frame-average", {{"frames", 4}});
  const std::string run_id = run["id"];

  // Listed under the run: the average, the first DNG, the preview.
  const json listed = api.get("/v1/runs/" + run_id + "/blobs");
  std::map<std::string, json> by_kind;
  for (const auto& item : listed["items"]) by_kind[item["kind"].get<std::string>()] = item;
  ASSERT_TRUE(by_kind.count("average")) << listed.dump(2);
  ASSERT_TRUE(by_kind.count("raw")) << listed.dump(2);
  ASSERT_TRUE(by_kind.count("preview")) << listed.dump(2);
  const json average = by_kind["average"], raw = by_kind["raw"];
  EXPECT_EQ(raw["media_type"], "image/x-adobe-dng");
  EXPECT_EQ(average["media_type"], "application/x-colorlab-array");
  EXPECT_EQ(average["meta"]["frames"], 4);
  EXPECT_EQ(by_kind["preview"]["meta"]["preview_of"], average["sha256"]);
  EXPECT_EQ(average["links"]["self"], "/v1/blobs/" + average["sha256"].get<std::string>());
  EXPECT_TRUE(average["name"].get<std::string>().rfind("camera.capture#", 0) == 0) << average["name"];

  // The DNG byte-exact through the API, and named by the SHA-256 of those bytes (sha256sum).
  const std::string raw_url = daemon.url() + "/v1/blobs/" + raw["sha256"].get<std::string>();
  const auto raw_path = blob_file(daemon.state_dir(), raw["sha256"]);
  const std::string raw_bytes = read_all(raw_path);
  ASSERT_EQ(raw_bytes.size(), raw["size"].get<std::size_t>());
  EXPECT_EQ(sha256sum(raw_path), raw["sha256"]);
  Fetched whole = curl(raw_url, {}, dir.path());
  EXPECT_EQ(whole.status, 200);
  EXPECT_TRUE(whole.body == raw_bytes);
  EXPECT_EQ(whole.headers["content-type"], "image/x-adobe-dng");
  EXPECT_EQ(whole.headers["etag"], "\"" + raw["sha256"].get<std::string>() + "\"");
  EXPECT_EQ(whole.headers["accept-ranges"], "bytes");
  EXPECT_EQ(whole.headers["content-length"], std::to_string(raw_bytes.size()));

  // One range: 206 with exactly those bytes; a suffix; beyond the end: 416.
  Fetched part = curl(raw_url, {"-r", "100-1099"}, dir.path());
  EXPECT_EQ(part.status, 206);
  EXPECT_EQ(part.headers["content-range"], "bytes 100-1099/" + std::to_string(raw_bytes.size()));
  EXPECT_TRUE(part.body == raw_bytes.substr(100, 1000));
  Fetched tail = curl(raw_url, {"-H", "Range: bytes=-77"}, dir.path());
  EXPECT_EQ(tail.status, 206);
  EXPECT_TRUE(tail.body == raw_bytes.substr(raw_bytes.size() - 77));
  Fetched beyond = curl(raw_url, {"-H", "Range: bytes=" + std::to_string(raw_bytes.size()) + "-"}, dir.path());
  EXPECT_EQ(beyond.status, 416);
  EXPECT_EQ(beyond.headers["content-range"], "bytes */" + std::to_string(raw_bytes.size()));
  // A range under an If-Range that is not this ETag: the whole body.
  Fetched stale = curl(raw_url, {"-r", "0-9", "-H", "If-Range: \"something-else\""}, dir.path());
  EXPECT_EQ(stale.status, 200);
  EXPECT_EQ(stale.body.size(), raw_bytes.size());

  // The ETag again: 304 without a body; HEAD: the headers alone.
  Fetched cached = curl(raw_url, {"-H", "If-None-Match: " + whole.headers["etag"]}, dir.path());
  EXPECT_EQ(cached.status, 304);
  EXPECT_TRUE(cached.body.empty());
  EXPECT_EQ(cached.headers["etag"], whole.headers["etag"]);
  Fetched head = curl(raw_url, {"-I"}, dir.path());
  EXPECT_EQ(head.status, 200);
  EXPECT_EQ(head.headers["content-length"], std::to_string(raw_bytes.size()));
  EXPECT_EQ(head.body.rfind("HTTP/", 0), 0u);  // with -I curl writes the headers as its output: no body came
  EXPECT_LT(head.body.size(), 2000u);

  // The average as a float array, described by its headers; its noise is the run's own Table 2 row.
  Fetched avg = curl(daemon.url() + "/v1/blobs/" + average["sha256"].get<std::string>(), {}, dir.path());
  ASSERT_EQ(avg.status, 200);
  EXPECT_EQ(avg.headers["content-type"], "application/x-colorlab-array");
  ASSERT_EQ(avg.headers["x-colorlab-dtype"], "<f4");
  const std::string cfa = avg.headers["x-colorlab-cfa"];
  ASSERT_EQ(cfa.size(), 4u) << cfa;
  std::smatch shape;
  const std::string shape_header = avg.headers["x-colorlab-shape"];
  ASSERT_TRUE(std::regex_match(shape_header, shape, std::regex(R"((\d+),(\d+))"))) << shape_header;
  const std::size_t height = std::stoul(shape[1]), width = std::stoul(shape[2]);
  ASSERT_EQ(avg.body.size(), height * width * 4);
  std::vector<float> values(height * width);
  std::memcpy(values.data(), avg.body.data(), avg.body.size());  // "<f4": little-endian, as this machine
  int compared = 0;
  for (const auto& m : run["measurements"]) {
    const std::string step = m["step"];
    if (step.rfind("noise/N4/", 0) != 0) continue;
    const char colour = step.back();
    const double recomputed = region_stdev(values, width, cfa, m["data"]["region"], colour);
    // The float32 average holds each mean to 2^-24 of itself: far below the noise's last digit.
    EXPECT_NEAR(recomputed, m["value"].get<double>(), 1e-4 * m["value"].get<double>()) << step;
    ++compared;
  }
  EXPECT_EQ(compared, 3);

  // A PNG preview of the average (and of the DNG, rendered on request).
  Fetched png = curl(daemon.url() + "/v1/blobs/" + average["sha256"].get<std::string>() + "/preview.png", {}, dir.path());
  EXPECT_EQ(png.status, 200);
  EXPECT_EQ(png.headers["content-type"], "image/png");
  EXPECT_EQ(png.body.substr(1, 3), "PNG");
  Fetched raw_png = curl(raw_url + "/preview.png", {}, dir.path());
  EXPECT_EQ(raw_png.status, 200);
  EXPECT_EQ(raw_png.body.substr(1, 3), "PNG");

  // The CLI lists the run's frames as the API does and downloads one byte for byte (and exits 2 on a refusal).
  auto listed_cli = run_command({bin_path("colorlab"), "--url", daemon.url(), "--json", "blobs", run_id});
  ASSERT_EQ(listed_cli.exit_code, 0) << listed_cli.err;
  EXPECT_EQ(json::parse(listed_cli.out)["items"], listed["items"]);
  const auto downloaded = dir / "downloaded.dng";
  auto got = run_command({bin_path("colorlab"), "--url", daemon.url(), "download", raw["sha256"].get<std::string>(), "-o",
                          downloaded.string()});
  ASSERT_EQ(got.exit_code, 0) << got.err;
  EXPECT_TRUE(read_all(downloaded) == raw_bytes);
  auto missing = run_command({bin_path("colorlab"), "--url", daemon.url(), "download", std::string(64, '0')});
  EXPECT_EQ(missing.exit_code, 2) << missing.err;
  // --json: one object saying what was written (into a directory: named by the hash), the bytes the same.
  const auto into = dir / "into";
  std::filesystem::create_directories(into);
  auto described = run_command({bin_path("colorlab"), "--url", daemon.url(), "--json", "download",
                                raw["sha256"].get<std::string>(), "-o", into.string()});
  ASSERT_EQ(described.exit_code, 0) << described.err;
  const json d = json::parse(described.out);
  EXPECT_EQ(d["sha256"], raw["sha256"]);
  EXPECT_EQ(d["bytes"].get<std::size_t>(), raw_bytes.size());
  EXPECT_EQ(d["preview"], false);
  EXPECT_GE(d["seconds"].get<double>(), 0.0);
  EXPECT_EQ(std::filesystem::path(d["path"].get<std::string>()).parent_path(), std::filesystem::absolute(into));
  EXPECT_TRUE(read_all(d["path"].get<std::string>()) == raw_bytes);
  // The frame's bytes and a JSON description cannot share stdout: refused before anything is fetched.
  auto no_file = run_command({bin_path("colorlab"), "--url", daemon.url(), "--json", "download", raw["sha256"].get<std::string>()});
  EXPECT_EQ(no_file.exit_code, 1) << no_file.out;
  EXPECT_NE(no_file.err.find("-o"), std::string::npos) << no_file.err;
  EXPECT_TRUE(no_file.out.empty());

  // Unknown blobs and runs: problem+json 404.
  Fetched unknown = curl(daemon.url() + "/v1/blobs/" + std::string(64, '0'), {}, dir.path());
  EXPECT_EQ(unknown.status, 404);
  EXPECT_EQ(unknown.headers["content-type"], "application/problem+json");
  EXPECT_EQ(curl(daemon.url() + "/v1/runs/nope/blobs", {}, dir.path()).status, 404);
}

TEST(BlobApi, TheNextStartReportsOrphansAndMissingFilesAndDeletesNothing) {
  TempDir dir;
  write_dslr_lab(dir.path());
  std::string orphan_sha, missing_sha;
  {
    DaemonProcess daemon(dir / "state", dir / "colorlabd.toml", dir / "colorlabd.log");
    auto api = api_for(daemon);
    EXPECT_TRUE(wait_for_check(api)["ok"]);  // a fresh store is whole
    const json run = run_to_end(api, "frame-average", {{"frames", 2}});
    const json listed = api.get("/v1/runs/" + run["id"].get<std::string>() + "/blobs");
    for (const auto& item : listed["items"]) {
      if (item["kind"] == "raw") missing_sha = item["sha256"];
    }
    ASSERT_FALSE(missing_sha.empty()) << listed.dump();
    EXPECT_EQ(daemon.terminate(), 0);
  }
  // A file without a row (as a crash between file and step leaves), a row without its file.
  const std::string content = "bytes no step ever committed";
  std::ofstream(dir / "orphan") << content;
  orphan_sha = sha256sum(dir / "orphan");
  std::filesystem::create_directories(blob_file(dir / "state", orphan_sha).parent_path());
  std::filesystem::copy_file(dir / "orphan", blob_file(dir / "state", orphan_sha));
  std::filesystem::remove(blob_file(dir / "state", missing_sha));

  DaemonProcess daemon(dir / "state", dir / "colorlabd.toml", dir / "colorlabd.log");
  auto api = api_for(daemon);
  const json report = wait_for_check(api);
  ASSERT_EQ(report["state"], "done") << report.dump();
  EXPECT_FALSE(report["ok"]);
  EXPECT_EQ(shas(report["orphans"]), std::set<std::string>{orphan_sha});
  EXPECT_EQ(shas(report["missing"]), std::set<std::string>{missing_sha});
  EXPECT_TRUE(std::filesystem::exists(blob_file(dir / "state", orphan_sha)));  // reported, not deleted
  // The event log has the check.
  const json events = api.get("/v1/events?topic=blobs");
  ASSERT_FALSE(events["items"].empty());
  const json last = events["items"].back()["payload"];
  EXPECT_EQ(last["event"], "check");
  EXPECT_EQ(last["orphans_count"], 1);
  EXPECT_EQ(last["missing_count"], 1);
  // The missing blob is a 404 that says where to look, not a server error.
  auto missing = api.request("GET", "/v1/blobs/" + missing_sha);
  EXPECT_EQ(missing.status, 404);
}

// The run_blobs rows that name any of these blobs, read from the database of a killed daemon.
int rows_naming(const std::filesystem::path& state, const std::set<std::string>& blobs) {
  sqlite3* db = nullptr;
  EXPECT_EQ(sqlite3_open_v2((state / "colorlab.db").c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  int n = 0;
  for (const auto& sha : blobs) {
    sqlite3_stmt* st = nullptr;
    sqlite3_prepare_v2(db, "SELECT COUNT(*) FROM run_blobs WHERE sha256 = ?1", -1, &st, nullptr);
    sqlite3_bind_text(st, 1, sha.c_str(), -1, SQLITE_TRANSIENT);
    if (sqlite3_step(st) == SQLITE_ROW) n += sqlite3_column_int(st, 0);
    sqlite3_finalize(st);
  }
  sqlite3_close(db);
  return n;
}

// kill -9 after a capture's frames are in the store but before its step is committed (the script
// computes for a while before its next lab call): the files have no row, and the next start says so.
TEST(BlobApi, KillNineBetweenFileAndRowLeavesAnOrphanTheNextStartReports) {
  // The kill has to land in the computation; on a machine so loaded that the step commits first, try
  // again on a fresh state.
  for (int attempt = 0; attempt < 3; ++attempt) {
    TempDir dir;
    write_dslr_lab(dir.path());
    write_campaign(dir.path(), "capture-then-think.lua", R"lua(
return {
  description = "test: a capture, then a long computation before the next lab call",
  needs = { "camera" },
  parameters = {},
  run = function(p)
    local t = lab.camera.capture({ frames = 2 })
    local x = 0
    for i = 1, 30000000 do x = (x + i) % 1000003 end
    lab.wait(0)
    return { x = x, blobs = #t.blobs }
  end,
}
)lua");
    std::set<std::string> at_kill;
    {
      DaemonProcess daemon(dir / "state", dir / "colorlabd.toml", dir / "colorlabd.log");
      auto api = api_for(daemon);
      wait_for_check(api);
      api.post("/v1/executions", {{"campaign", "capture-then-think"}, {"params", json::object()}});
      // Three files (average, DNG, preview) appear, then the computation starts.
      for (int i = 0; i < 30000 && at_kill.size() < 3; ++i) {
        at_kill.clear();
        std::error_code ec;
        for (auto& f : std::filesystem::recursive_directory_iterator(dir / "state" / "blobs", ec)) {
          const std::string name = f.path().filename().string();
          if (f.is_regular_file() && name.rfind(".tmp-", 0) != 0) at_kill.insert(f.path().parent_path().filename().string() + name);
        }
        if (at_kill.size() < 3) std::this_thread::sleep_for(std::chrono::milliseconds(2));
      }
      ASSERT_EQ(at_kill.size(), 3u) << shell_output("tail -20 " + (dir / "colorlabd.log").string());
      daemon.kill9();
    }
    if (rows_naming(dir / "state", at_kill) > 0) continue;  // the step committed before the kill
    DaemonProcess daemon(dir / "state", dir / "colorlabd.toml", dir / "colorlabd.log");
    auto api = api_for(daemon);
    const json report = wait_for_check(api);
    ASSERT_EQ(report["state"], "done") << report.dump();
    EXPECT_EQ(shas(report["orphans"]), at_kill);
    EXPECT_TRUE(report["missing"].empty());
    for (const auto& s : at_kill) EXPECT_TRUE(std::filesystem::exists(blob_file(dir / "state", s)));
    return;
  }
  FAIL() << "each of three kills came after the step had committed";
}

// kill -9 after the capture's step (files and rows) was committed: the resumed run answers the capture
// from its journal — no new frames — and the run's blobs are exactly those it kept before the kill.
TEST(BlobApi, AResumedRunKeepsTheBlobsItsJournalNames) {
  TempDir dir;
  write_dslr_lab(dir.path());
  write_campaign(dir.path(), "capture-then-ask.lua", R"lua(
return {
  description = "test: a capture, then an operator request the test answers after a kill -9",
  needs = { "camera" },
  parameters = {},
  run = function(p)
    local t = lab.camera.capture({ frames = 2 })
    local a = lab.operator.request { action = "test_wait", prompt = "go on", options = { "go" }, default = "go",
                                     timeout_s = 100000 }
    return { blobs = t.blobs, answer = a.answer }
  end,
}
)lua");
  json before;
  std::string execution_id, run_id;
  {
    DaemonProcess daemon(dir / "state", dir / "colorlabd.toml", dir / "colorlabd.log");
    auto api = api_for(daemon);
    auto e = api.post("/v1/executions", {{"campaign", "capture-then-ask"}, {"params", json::object()}});
    execution_id = e["id"];
    run_id = e["run_id"];
    // The request is posted only after the capture's step was committed (the commit precedes the next call).
    for (int i = 0; i < 600 && api.get("/v1/requests")["items"].empty(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    ASSERT_FALSE(api.get("/v1/requests")["items"].empty());
    before = api.get("/v1/runs/" + run_id + "/blobs")["items"];
    ASSERT_EQ(before.size(), 3u) << before.dump();
    daemon.kill9();
  }
  DaemonProcess daemon(dir / "state", dir / "colorlabd.toml", dir / "colorlabd.log");
  auto api = api_for(daemon);
  json pending;
  for (int i = 0; i < 600 && pending.empty(); ++i) {
    auto items = api.get("/v1/requests")["items"];
    if (!items.empty()) pending = items[0];
    else std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_FALSE(pending.empty());
  api.post("/v1/requests/" + pending["id"].get<std::string>(), {{"answer", "go"}});
  auto done = wait_terminal(api, execution_id);
  ASSERT_EQ(done["status"], "finished_ok") << done.dump();
  const json after = api.get("/v1/runs/" + run_id + "/blobs")["items"];
  EXPECT_EQ(after, before);
  // The script saw the same references from the journal as it got live.
  json run = colorlab::client::fetch_run(api, run_id);
  std::set<std::string> from_script;
  for (const auto& b : run["summary"]["script"]["blobs"]) from_script.insert(b["sha256"].get<std::string>());
  EXPECT_EQ(from_script, shas(before));
  const json report = wait_for_check(api);
  EXPECT_TRUE(report["ok"]) << report.dump();
  EXPECT_EQ(report["files"], 3);
}

// characterize-camera keeps what its keep parameter names: the averaged raw, the first DNG, the
// first JPEG and a preview, listed under the run with their media types and the average's shape.
TEST(BlobApi, ChartPhotographKeepsTheAveragedRawAndTheCamerasOwnFiles) {
  TempDir dir;
  auto config = write_daemon_config(dir.path(), 500, 5);
  std::ofstream(dir / "lab.toml") << "[genicam]\nenabled = false\n[dslr]\nsize = [1752, 1168]\n";
  DaemonProcess daemon(dir / "state", config);
  auto api = api_for(daemon);
  json reference = run_to_end(api, "chart-read", json::object());
  json run = run_to_end(api, "characterize-camera",
                        {
                            {"reference_run", reference["id"]},
                            {"frames", 2},
                            {"formats", {"raw", "jpeg"}},
                            {"keep", {"average", "raw", "jpeg", "preview"}},
                            {"prior_exclude", {"Canon_20D"}},
                        },
                        std::chrono::seconds(300));
  const json listed = api.get("/v1/runs/" + run["id"].get<std::string>() + "/blobs");
  std::map<std::string, json> by_kind;
  for (const auto& item : listed["items"]) by_kind[item["kind"].get<std::string>()] = item;
  ASSERT_EQ(by_kind.size(), 4u) << listed.dump(2);
  EXPECT_EQ(by_kind["average"]["meta"]["dtype"], "<f4");
  EXPECT_EQ(by_kind["average"]["meta"]["frames"], 2);
  EXPECT_EQ(by_kind["average"]["meta"]["shape"].size(), 2u);
  EXPECT_EQ(by_kind["average"]["size"].get<std::size_t>(),
            4 * by_kind["average"]["meta"]["shape"][0].get<std::size_t>() * by_kind["average"]["meta"]["shape"][1].get<std::size_t>());
  EXPECT_TRUE(by_kind["average"]["name"].get<std::string>().find("/raw/average") != std::string::npos) << by_kind["average"]["name"];
  EXPECT_EQ(by_kind["raw"]["media_type"], "image/x-adobe-dng");
  EXPECT_EQ(by_kind["jpeg"]["media_type"], "image/jpeg");
  EXPECT_EQ(by_kind["preview"]["meta"]["preview_of"], by_kind["average"]["sha256"]);
  // The files are what they say: a JPEG's and a TIFF-based DNG's first bytes.
  const std::string jpeg = read_all(blob_file(daemon.state_dir(), by_kind["jpeg"]["sha256"]));
  ASSERT_GE(jpeg.size(), 2u);
  EXPECT_EQ(static_cast<unsigned char>(jpeg[0]), 0xFF);
  EXPECT_EQ(static_cast<unsigned char>(jpeg[1]), 0xD8);
  const std::string dng = read_all(blob_file(daemon.state_dir(), by_kind["raw"]["sha256"]));
  ASSERT_GE(dng.size(), 4u);
  EXPECT_TRUE(dng.substr(0, 4) == std::string("II*\0", 4) || dng.substr(0, 4) == std::string("MM\0*", 4));
}
