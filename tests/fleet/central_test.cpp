// colorlab-central (issue 22, the central read API) against a real PostgreSQL 15 and a real Swift s3api on
// 127.0.0.1: a bench (colorlabd on its simulated lab) runs a chart-read and a frame-average, colorlab-ship ships
// them, and for the same runs central's documents, measurement pages, exports and blobs equal the bench's (the
// `bench` member aside); the CLI and the Python client give the same answers with only the URL changed. Two more
// benches (SimBench, rows written as colorlabd writes them) give the run list something to page and filter
// across. Control requests are refused as read-only, and a wrong key as on a bench. The servers, the benches
// and central start once per process (World): their start-up is most of the cost.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <set>

#include <nlohmann/json.hpp>

#include "colorlab/client/api_client.hpp"
#include "colorlab/fleet/pg.hpp"
#include "colorlab/fleet/s3.hpp"
#include "colorlab/testing/daemon.hpp"
#include "colorlab/testing/process.hpp"
#include "fleet_servers.hpp"
#include "resume_support.hpp"
#include "sim_bench.hpp"

namespace fs = std::filesystem;
using namespace colorlab;
namespace ct = colorlab::testing;
using namespace colorlab::fleet_test;
using nlohmann::json;
using protocol::ExecutionStatus;

namespace {

struct Reply {
  int status = 0;
  std::map<std::string, std::string> headers;  // lower-case names
  std::string body;
  json doc() const { return json::parse(body); }
};

// One request with curl, an independent client: status, headers and body as received.
Reply curl(const std::string& url, const std::vector<std::string>& args, const fs::path& dir) {
  const auto head = dir / "curl.headers", body = dir / "curl.body";
  fs::remove(head);
  fs::remove(body);
  std::vector<std::string> argv = {"/usr/bin/curl", "-s", "-D", head.string(), "-o", body.string()};
  argv.insert(argv.end(), args.begin(), args.end());
  argv.push_back(url);
  auto r = ct::run_command(argv, std::chrono::seconds(60));
  EXPECT_EQ(r.exit_code, 0) << url << ": " << r.err;
  Reply f;
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
    f.headers[name] = line.substr(std::min(line.size(), line.find_first_not_of(' ', colon + 1)));
  }
  f.body = read_all(body);
  return f;
}

// Everything the tests share, started once: the servers, three benches shipped into one database and bucket,
// and colorlab-central over them.
struct World {
  fs::path root;
  std::unique_ptr<PostgresServer> pg;
  std::unique_ptr<SwiftServer> swift;
  std::unique_ptr<ct::DaemonProcess> bench;  // bench-a: colorlabd on its simulated lab
  std::unique_ptr<SimBench> bench_b, bench_c;
  fs::path bench_b_config, bench_c_config;
  std::unique_ptr<ct::Process> central;
  std::string bench_url, central_url, key;
  std::string chart_run, frame_run;  // bench-a's runs
  std::vector<std::string> b_runs, c_runs;
  std::string failure;  // set when the start-up failed: every test fails with it

  ShipTarget target() const {
    return {pg->conninfo("central"), swift->endpoint(), "central", SwiftServer::kAccessKey, SwiftServer::kSecretKey};
  }

  ~World() {
    central.reset();
    bench.reset();
    bench_b.reset();
    bench_c.reset();
    swift.reset();
    pg.reset();
    std::error_code ec;
    fs::remove_all(root, ec);
  }
};

ct::RunResult ship(const fs::path& config) {
  return ct::run_command({ct::bin_path("colorlab-ship"), "--config", config.string(), "once"}, std::chrono::seconds(120));
}

void start_world(World& w) {
  const auto t0 = std::chrono::steady_clock::now();
  w.root = fs::path(COLORLAB_BIN_DIR).parent_path() / "tests" / "fleet-central-scratch" / std::to_string(::getpid());
  fs::remove_all(w.root);
  fs::create_directories(w.root);
  w.pg = std::make_unique<PostgresServer>(fs::temp_directory_path() / ("colorlab-central-pg-" + std::to_string(::getpid())));
  w.pg->start();
  w.pg->psql("postgres", "CREATE DATABASE central");
  w.swift = std::make_unique<SwiftServer>(w.root / "swift");
  w.swift->create_bucket("central");
  const auto t1 = std::chrono::steady_clock::now();

  // bench-a: a real colorlabd on its simulated lab (no GigE camera: another test's may hold 127.0.0.1), a small DSLR.
  const fs::path a = w.root / "bench-a";
  fs::create_directories(a);
  auto daemon_config = ct::write_daemon_config(a, 500, 11);
  std::ofstream(a / "lab.toml") << "[genicam]\nenabled = false\n[dslr]\nsize = [640, 428]\n";
  w.bench = std::make_unique<ct::DaemonProcess>(a / "state", daemon_config, a / "colorlabd.log");
  w.bench_url = w.bench->url();
  auto api = ct::api_for(*w.bench);
  w.chart_run = ct::run_to_end(api, "chart-read", {{"chart", "cc24"}})["id"];
  w.frame_run = ct::run_to_end(api, "frame-average", {{"frames", 2}})["id"];
  const auto t2 = std::chrono::steady_clock::now();

  ShipTarget t = w.target();
  std::ofstream(a / "s3-access-key") << t.access_key << "\n";
  std::ofstream(a / "s3-secret-key") << t.secret_key << "\n";
  const fs::path a_ship = a / "ship.toml";
  std::ofstream(a_ship) << "state_dir = \"" << (a / "state").string() << "\"\n[ship]\nbench_id = \"bench-a\"\n"
                        << "bench_name = \"Bench A (colorlabd)\"\npostgres = \"" << t.postgres << "\"\n"
                        << "s3_endpoint = \"" << t.s3_endpoint << "\"\nbucket = \"central\"\n"
                        << "access_key_file = \"s3-access-key\"\nsecret_key_file = \"s3-secret-key\"\n";
  auto r = ship(a_ship);
  if (r.exit_code != 0) throw std::runtime_error("shipping bench-a: " + r.err);

  // bench-b and bench-c: more runs, mixed statuses, to page and filter across benches.
  w.bench_b = std::make_unique<SimBench>(w.root / "bench-b", "bench-b", 21);
  const ExecutionStatus b_status[] = {ExecutionStatus::finished_ok, ExecutionStatus::aborted,
                                      ExecutionStatus::finished_ok, ExecutionStatus::finished_error,
                                      ExecutionStatus::finished_ok, ExecutionStatus::aborted, ExecutionStatus::finished_ok};
  for (auto s : b_status) w.b_runs.push_back(w.bench_b->run_campaign(s, 6, 3));
  w.bench_b_config = w.bench_b->write_config(t);
  r = ship(w.bench_b_config);
  if (r.exit_code != 0) throw std::runtime_error("shipping bench-b: " + r.err);
  w.bench_c = std::make_unique<SimBench>(w.root / "bench-c", "bench-c", 31);
  for (int i = 0; i < 5; ++i) w.c_runs.push_back(w.bench_c->run_campaign(ExecutionStatus::finished_ok, 4, 0));
  // Two runs a cycle: after one cycle three ended runs wait on the bench, which GET /v1/benches shows as its lag.
  w.bench_c_config = w.bench_c->write_config(t, 2);
  r = ship(w.bench_c_config);
  if (r.exit_code != 0) throw std::runtime_error("shipping bench-c: " + r.err);
  const auto t3 = std::chrono::steady_clock::now();

  // colorlab-central, with one key.
  const fs::path c = w.root / "central";
  fs::create_directories(c);
  std::ofstream(c / "s3-access-key") << t.access_key << "\n";
  std::ofstream(c / "s3-secret-key") << t.secret_key << "\n";
  std::ofstream(c / "central.toml") << "state_dir = \"" << (c / "state").string() << "\"\n[central]\n"
                                    << "listen = \"127.0.0.1\"\nport = 0\nthreads = 2\npostgres = \"" << t.postgres
                                    << "\"\ns3_endpoint = \"" << t.s3_endpoint << "\"\nbucket = \"central\"\n"
                                    << "access_key_file = \"s3-access-key\"\nsecret_key_file = \"s3-secret-key\"\n";
  r = ct::run_command({ct::bin_path("colorlab-central"), "--config", (c / "central.toml").string(), "keys", "create",
                       "tester"});
  if (r.exit_code != 0) throw std::runtime_error("colorlab-central keys create: " + r.err);
  w.key = json::parse(r.out)["key"];
  w.central = std::make_unique<ct::Process>(
      std::vector<std::string>{ct::bin_path("colorlab-central"), "--config", (c / "central.toml").string(), "serve"},
      c / "central.log");
  auto line = w.central->read_line(std::chrono::seconds(60));
  if (!line) throw std::runtime_error("colorlab-central did not start: " + read_all(c / "central.log"));
  w.central_url = json::parse(*line)["url"];
  const auto t4 = std::chrono::steady_clock::now();
  auto s = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
  std::cerr << "central world: servers " << s(t0, t1) << " s (PostgreSQL " << w.pg->start_seconds << ", Swift "
            << w.swift->start_seconds << "), bench-a's two campaigns " << s(t1, t2) << " s, shipping " << s(t2, t3)
            << " s, central up " << s(t3, t4) << " s\n";
}

World& world() {
  static World w;
  static bool tried = false;
  if (!tried) {
    tried = true;
    try {
      start_world(w);
    } catch (const std::exception& e) {
      w.failure = e.what();
    }
  }
  return w;
}

class Central : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string missing = missing_tools();
    // The brief of these tests: a machine without the servers fails them (scripts/setup.sh installs them).
    if (!missing.empty()) FAIL() << "the central tests need:" << missing << " (scripts/setup.sh installs them)";
    auto& w = world();
    if (!w.failure.empty()) FAIL() << "start-up failed: " << w.failure;
    dir_ = w.root / "curl";
    fs::create_directories(dir_);
  }
  World& w() { return world(); }
  Reply central(const std::string& path, std::vector<std::string> args = {}) {
    args.insert(args.end(), {"-H", "Authorization: Bearer " + w().key});
    return curl(w().central_url + path, args, dir_);
  }
  Reply bench(const std::string& path, std::vector<std::string> args = {}) {
    return curl(w().bench_url + path, args, dir_);
  }
  fs::path dir_;
};

// What the bench's run document has that central's does not, and the other way round.
json without_bench_fields(json doc) {
  doc.erase("bench");
  if (doc.contains("links")) doc["links"].erase("report");  // reports are made on a bench
  return doc;
}

TEST_F(Central, RunDocumentsMeasurementPagesAndExportsEqualTheBenchs) {
  for (const std::string& id : {w().chart_run, w().frame_run}) {
    SCOPED_TRACE(id);
    auto b = bench("/v1/runs/" + id), c = central("/v1/runs/" + id);
    ASSERT_EQ(b.status, 200);
    ASSERT_EQ(c.status, 200) << c.body;
    EXPECT_EQ(without_bench_fields(c.doc()), without_bench_fields(b.doc()));
    EXPECT_EQ(c.doc()["bench"], json({{"id", "bench-a"}, {"name", "Bench A (colorlabd)"}}));

    // Measurement pages: a small page size makes several pages; items and cursors equal page by page.
    for (const std::string filter : {"", "&quantity=reflectance_spectrum", "&step_prefix=patch/"}) {
      std::string path = "/v1/runs/" + id + "/measurements?limit=7" + filter;
      int pages = 0;
      while (true) {
        auto bp = bench(path), cp = central(path);
        ASSERT_EQ(cp.status, 200) << cp.body;
        EXPECT_EQ(cp.doc(), bp.doc()) << path;
        ++pages;
        if (bp.doc()["next_cursor"].is_null() || pages > 100) break;
        path = bp.doc()["links"]["next"];
      }
    }
    for (const std::string format : {"csv", "json", "ti3"}) {
      auto be = bench("/v1/runs/" + id + "/export?format=" + format);
      auto ce = central("/v1/runs/" + id + "/export?format=" + format);
      EXPECT_EQ(ce.status, be.status) << format << ": " << ce.body;
      if (be.status == 200) {
        EXPECT_EQ(ce.body, be.body) << format;
        EXPECT_EQ(ce.headers["content-type"], be.headers["content-type"]);
        EXPECT_EQ(ce.headers["content-disposition"], be.headers["content-disposition"]);
      } else {  // frame-average has no patches: both refuse the .ti3 alike
        EXPECT_EQ(ce.doc()["code"], be.doc()["code"]);
      }
    }
    // The run's blobs: the same list, without the preview central does not render.
    auto bb = bench("/v1/runs/" + id + "/blobs").doc(), cb = central("/v1/runs/" + id + "/blobs").doc();
    for (auto* list : {&bb, &cb}) {
      for (auto& item : (*list)["items"]) item.erase("links");
    }
    EXPECT_EQ(cb, bb);
  }
  EXPECT_EQ(bench("/v1/runs/" + w().chart_run + "/export?format=ti3").status, 200) << "the chart-read makes a .ti3";
}

TEST_F(Central, TheCliAndThePythonClientWorkWithOnlyTheUrlChanged) {
  // Central's key is central's: the bench is read over loopback without one.
  auto cli = [&](const std::string& url, std::vector<std::string> args) {
    std::vector<std::string> argv = {ct::bin_path("colorlab"), "--url", url, "--json"};
    if (url == w().central_url) argv.insert(argv.begin() + 3, {"--key", w().key});
    argv.insert(argv.end(), args.begin(), args.end());
    auto r = ct::run_command(argv, std::chrono::seconds(60));
    EXPECT_EQ(r.exit_code, 0) << url << ": " << r.err;
    return r.out;
  };
  const std::string id = w().chart_run;
  EXPECT_EQ(without_bench_fields(json::parse(cli(w().central_url, {"show", id}))),
            without_bench_fields(json::parse(cli(w().bench_url, {"show", id}))));
  EXPECT_EQ(cli(w().central_url, {"export", id, "--format", "ti3"}), cli(w().bench_url, {"export", id, "--format", "ti3"}));
  auto listed = json::parse(cli(w().central_url, {"runs", "--limit", "50"}));
  std::set<std::string> ids;
  for (const auto& r : listed["items"]) ids.insert(r["id"]);
  EXPECT_TRUE(ids.count(w().chart_run) && ids.count(w().frame_run) && ids.count(w().b_runs.front()));

  // pandas: the same DataFrames of measurements, spectra and blobs from both URLs (central_client_check.py).
  auto py = ct::run_command({"/usr/bin/env", "PYTHONPATH=" COLORLAB_SOURCE_DIR "/client/python", "PYTHONDONTWRITEBYTECODE=1",
                             "/usr/bin/python3", COLORLAB_SOURCE_DIR "/tests/fleet/central_client_check.py",
                             w().bench_url, w().central_url, w().key, w().chart_run, w().frame_run},
                            std::chrono::seconds(120));
  EXPECT_EQ(py.exit_code, 0) << py.out << py.err;
  EXPECT_NE(py.out.find("equal DataFrames"), std::string::npos) << py.out;
}

TEST_F(Central, RunsPageAcrossBenchesAndFilter) {
  // Every run central holds, newest first (UUIDv7 order), a page of 3 at a time: each exactly once.
  std::vector<std::string> paged;
  std::string path = "/v1/runs?limit=3";
  for (int i = 0; i < 100; ++i) {
    auto r = central(path);
    ASSERT_EQ(r.status, 200) << r.body;
    auto doc = r.doc();
    EXPECT_LE(doc["items"].size(), 3u);
    for (const auto& item : doc["items"]) paged.push_back(item["id"]);
    if (doc["links"]["next"].is_null()) break;
    path = doc["links"]["next"];
  }
  fleet::Pg pg(w().pg->conninfo("central"));
  auto all = pg.query("SELECT id FROM runs ORDER BY id DESC");
  std::vector<std::string> expected;
  for (int i = 0; i < all.rows(); ++i) expected.push_back(all.text(i, 0));
  EXPECT_EQ(paged, expected);
  EXPECT_GE(paged.size(), 2u + 7u + 2u) << "bench-a's two, bench-b's seven, at least bench-c's first two";

  auto ids_of = [&](const std::string& query) {
    std::vector<std::string> out;
    std::string p = "/v1/runs?limit=2&" + query;
    for (int i = 0; i < 100; ++i) {
      auto r = central(p);
      EXPECT_EQ(r.status, 200) << r.body;
      if (r.status != 200) break;
      const json doc = r.doc();
      for (const auto& item : doc["items"]) out.push_back(item["id"]);
      if (doc["links"]["next"].is_null()) break;
      p = doc["links"]["next"];
    }
    return out;
  };
  auto b = ids_of("bench=bench-b");
  std::vector<std::string> b_expected(w().b_runs.rbegin(), w().b_runs.rend());
  EXPECT_EQ(b, b_expected) << "bench-b's runs, newest first, through pages that keep the filter";
  auto aborted = ids_of("bench=bench-b&status=aborted");
  EXPECT_EQ(aborted, (std::vector<std::string>{w().b_runs[5], w().b_runs[1]}));
  EXPECT_EQ(ids_of("campaign=frame-average"), std::vector<std::string>{w().frame_run});
  // Time: since the creation of bench-b's fourth run, until that of its sixth (exclusive). Runs made within the same
  // millisecond share a time, so the expectation comes from the runs' own created_at (ISO 8601 UTC, one format:
  // text order is time order), newest first.
  auto created = [&](const std::string& id) { return central("/v1/runs/" + id).doc()["created_at"].get<std::string>(); };
  const std::string since = created(w().b_runs[3]), until = created(w().b_runs[5]);
  std::vector<std::string> in_window;
  for (auto it = w().b_runs.rbegin(); it != w().b_runs.rend(); ++it) {
    const std::string t = created(*it);
    if (t >= since && t < until) in_window.push_back(*it);
  }
  EXPECT_EQ(ids_of("bench=bench-b&since=" + since + "&until=" + until), in_window);
  if (since < until) {
    EXPECT_FALSE(in_window.empty());
  }

  EXPECT_EQ(central("/v1/runs?cursor=not%20a%20cursor").status, 400);
  auto bad_time = central("/v1/runs?since=not-a-time");
  EXPECT_EQ(bad_time.status, 400);
  EXPECT_NE(bad_time.body.find("ISO 8601"), std::string::npos) << bad_time.body;
  EXPECT_EQ(central("/v1/runs/no-such-run").status, 404);
}

TEST_F(Central, BenchesShowTheirLag) {
  auto benches = [&] {
    std::map<std::string, json> out;
    const json doc = central("/v1/benches").doc();
    for (const auto& b : doc["items"]) out[b["id"]] = b;
    return out;
  };
  auto before = benches();
  ASSERT_EQ(before.size(), 3u);
  EXPECT_EQ(before["bench-a"]["lag"]["unshipped_runs"], 0);
  EXPECT_TRUE(before["bench-a"]["lag"]["oldest_unshipped_run"].is_null());
  EXPECT_EQ(before["bench-a"]["runs"], 2);
  // bench-c shipped two of its five in its one cycle: three wait, the oldest its third run.
  const json lag = before["bench-c"]["lag"];
  EXPECT_EQ(lag["unshipped_runs"], 3);
  EXPECT_EQ(lag["oldest_unshipped_run"], w().c_runs[2]);
  ASSERT_TRUE(lag["age_s"].is_number()) << lag.dump();
  EXPECT_GE(lag["age_s"].get<double>(), 0.0);
  EXPECT_EQ(before["bench-c"]["name"], "Simulated bench-c");

  auto unshipped = central("/v1/runs/" + w().c_runs[4]);
  EXPECT_EQ(unshipped.status, 404) << "not shipped yet";
  EXPECT_NE(unshipped.body.find("/v1/benches"), std::string::npos) << unshipped.body;

  // A listing central has answered (and keeps, central_cache.hpp) still shows what ships after it.
  auto listed = [&] {
    std::set<std::string> ids;
    const auto r = central("/v1/runs?limit=50");
    EXPECT_EQ(r.status, 200) << r.body;
    const json doc = r.doc();  // held: a range-for over a temporary's member would dangle
    for (const auto& item : doc.at("items")) ids.insert(item.at("id").get<std::string>());
    return ids;
  };
  EXPECT_EQ(listed().count(w().c_runs[4]), 0u);
  EXPECT_EQ(listed().count(w().c_runs[4]), 0u) << "asked again: the kept answer";

  // Two more cycles ship the rest: no lag left.
  for (int i = 0; i < 2; ++i) ASSERT_EQ(ship(w().bench_c_config).exit_code, 0);
  EXPECT_EQ(listed().count(w().c_runs[4]), 1u) << "a run shipped after the listing was kept is listed";
  auto after = benches();
  EXPECT_EQ(after["bench-c"]["lag"]["unshipped_runs"], 0);
  EXPECT_EQ(after["bench-c"]["runs"], 5);
  EXPECT_EQ(after["bench-c"]["lag"]["age_s"], 0.0);
  EXPECT_EQ(central("/v1/runs/" + w().c_runs[4]).status, 200);
}

// Pages and listings asked for again are the same bytes (kept in memory, central_cache.hpp) with an entity tag of
// those bytes; a client that holds them gets 304 (RFC 9110 §13.1.2), and an unknown run is still a 404.
TEST_F(Central, AnswersAskedAgainAreTheSameBytesWithAnEntityTag) {
  const std::string path = "/v1/runs/" + w().chart_run + "/measurements?limit=5";
  auto first = central(path), again = central(path);
  ASSERT_EQ(first.status, 200) << first.body;
  ASSERT_EQ(again.status, 200) << again.body;
  EXPECT_EQ(again.body, first.body);
  EXPECT_EQ(first.doc(), bench(path).doc());
  ASSERT_EQ(first.headers.count("etag"), 1u);
  EXPECT_EQ(again.headers["etag"], first.headers["etag"]);
  auto held = central(path, {"-H", "If-None-Match: " + first.headers["etag"]});
  EXPECT_EQ(held.status, 304);
  EXPECT_TRUE(held.body.empty());
  EXPECT_EQ(central(path, {"-H", "If-None-Match: \"0000000000000000\""}).status, 200);
  ASSERT_TRUE(first.doc()["next_cursor"].is_string());
  auto next = central(path + "&cursor=" + first.doc()["next_cursor"].get<std::string>());
  ASSERT_EQ(next.status, 200);
  EXPECT_NE(next.headers["etag"], first.headers["etag"]);

  auto listing = central("/v1/runs?limit=4");
  ASSERT_EQ(listing.status, 200);
  EXPECT_EQ(central("/v1/runs?limit=4", {"-H", "If-None-Match: " + listing.headers["etag"]}).status, 304);

  const std::string unknown = "/v1/runs/0190ffff-ffff-7fff-8fff-ffffffffffff/measurements";
  EXPECT_EQ(central(unknown).status, 404);
  EXPECT_EQ(central(unknown).status, 404) << "a 404 is not kept";
}

TEST_F(Central, BlobsComeFromTheBucketWithRangeAndETag) {
  auto listed = central("/v1/runs/" + w().frame_run + "/blobs").doc()["items"];
  ASSERT_FALSE(listed.empty());
  const std::string sha = listed[0]["sha256"];
  const std::string path = "/v1/blobs/" + sha;
  auto whole = central(path), on_bench = bench(path);
  ASSERT_EQ(whole.status, 200) << whole.body.substr(0, 300);
  EXPECT_EQ(whole.body, on_bench.body);
  EXPECT_EQ(fleet::sha256_hex(whole.body), sha);
  EXPECT_EQ(whole.headers["etag"], "\"" + sha + "\"");
  EXPECT_EQ(whole.headers["etag"], on_bench.headers["etag"]);
  EXPECT_EQ(whole.headers["content-type"], on_bench.headers["content-type"]);
  EXPECT_EQ(whole.headers["x-colorlab-shape"], on_bench.headers["x-colorlab-shape"]);
  EXPECT_EQ(whole.headers["accept-ranges"], "bytes");

  auto part = central(path, {"-H", "Range: bytes=100-1123"});
  EXPECT_EQ(part.status, 206);
  EXPECT_EQ(part.body, whole.body.substr(100, 1024));
  EXPECT_EQ(part.headers["content-range"], "bytes 100-1123/" + std::to_string(whole.body.size()));
  auto tail = central(path, {"-H", "Range: bytes=-10"});
  EXPECT_EQ(tail.status, 206);
  EXPECT_EQ(tail.body, whole.body.substr(whole.body.size() - 10));
  EXPECT_EQ(central(path, {"-H", "If-None-Match: \"" + sha + "\""}).status, 304);
  auto beyond = central(path, {"-H", "Range: bytes=" + std::to_string(whole.body.size() + 5) + "-"});
  EXPECT_EQ(beyond.status, 416);
  EXPECT_EQ(beyond.headers["content-range"], "bytes */" + std::to_string(whole.body.size()));
  // If-Range with another tag: the whole blob.
  EXPECT_EQ(central(path, {"-H", "Range: bytes=0-9", "-H", "If-Range: \"other\""}).status, 200);
  auto head = central(path, {"-I"});
  EXPECT_EQ(head.status, 200);
  EXPECT_EQ(head.headers["content-length"], std::to_string(whole.body.size()));
  EXPECT_EQ(central("/v1/blobs/" + std::string(64, '0')).status, 404);
}

// A blob far larger than what central holds of it at a time (S3Download::kPiece): every byte of the whole object
// and of ranges that start and end inside pieces comes through as the bucket has it. An object that does not hash
// to its name is cut short of its Content-Length, so no client takes it as complete.
TEST_F(Central, ALargeBlobIsRelayedByteForByteWholeAndInRanges) {
  constexpr std::size_t kSize = 24 * 1024 * 1024 + 12345;  // ~96 pieces, the last one partial
  std::string bytes(kSize, '\0');
  std::uint64_t x = 0x9e3779b97f4a7c15ull;  // xorshift64: bytes no piece boundary can line up with
  for (auto& b : bytes) {
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    b = static_cast<char>(x >> 56);
  }
  const std::string sha = fleet::sha256_hex(bytes);
  const fs::path file = dir_ / "large.bin";
  std::ofstream(file, std::ios::binary) << bytes;
  fleet::S3Client s3(w().swift->endpoint(), "central", "us-east-1", {SwiftServer::kAccessKey, SwiftServer::kSecretKey});
  s3.put_file("sha256/" + sha, file, sha);
  w().pg->psql("central", "INSERT INTO blobs (sha256, size, media_type, meta) VALUES ('" + sha + "', " +
                              std::to_string(kSize) + ", 'application/octet-stream', '{}') ON CONFLICT DO NOTHING");
  fs::remove(file);
  const std::string path = "/v1/blobs/" + sha;

  auto whole = central(path);
  ASSERT_EQ(whole.status, 200) << whole.body.substr(0, 300);
  EXPECT_EQ(whole.headers["content-length"], std::to_string(kSize));
  EXPECT_TRUE(whole.body == bytes) << "the whole blob differs (" << whole.body.size() << " bytes received)";
  const std::pair<std::uint64_t, std::uint64_t> ranges[] = {
      {1000003, 20000008}, {0, 0}, {262143, 262144}, {kSize - 1, kSize - 1}, {23000000, kSize - 1}};
  for (auto [first, last] : ranges) {
    SCOPED_TRACE(std::to_string(first) + "-" + std::to_string(last));
    auto part = central(path, {"-H", "Range: bytes=" + std::to_string(first) + "-" + std::to_string(last)});
    ASSERT_EQ(part.status, 206) << part.body.substr(0, 300);
    EXPECT_EQ(part.headers["content-range"],
              "bytes " + std::to_string(first) + "-" + std::to_string(last) + "/" + std::to_string(kSize));
    EXPECT_EQ(part.headers["content-length"], std::to_string(last - first + 1));
    EXPECT_TRUE(part.body == bytes.substr(first, last - first + 1)) << part.body.size() << " bytes received";
  }
  auto suffix = central(path, {"-H", "Range: bytes=-300000"});
  EXPECT_EQ(suffix.status, 206);
  EXPECT_TRUE(suffix.body == bytes.substr(kSize - 300000));
  auto head = central(path, {"-I"});
  EXPECT_EQ(head.status, 200);
  EXPECT_EQ(head.headers["content-length"], std::to_string(kSize));

  // Rotten: the object under this name holds other bytes (the store checks the upload's hash, not its name).
  const std::string rotten = fleet::sha256_hex(bytes.substr(0, 1000000) + "x");
  const fs::path other = dir_ / "rotten.bin";
  std::ofstream(other, std::ios::binary) << bytes.substr(0, 1000000);
  s3.put_file("sha256/" + rotten, other, fleet::sha256_hex(bytes.substr(0, 1000000)));
  fs::remove(other);
  w().pg->psql("central", "INSERT INTO blobs (sha256, size, media_type, meta) VALUES ('" + rotten +
                              "', 1000000, 'application/octet-stream', '{}') ON CONFLICT DO NOTHING");
  auto cut = ct::run_command({"/usr/bin/curl", "-s", "-o", (dir_ / "rotten.out").string(), "-H",
                              "Authorization: Bearer " + w().key, w().central_url + "/v1/blobs/" + rotten},
                             std::chrono::seconds(60));
  EXPECT_EQ(cut.exit_code, 18) << "curl should see a body short of its Content-Length (CURLE_PARTIAL_FILE)";
  // curl writes no file when no byte came (the object fits in the one piece held back).
  std::error_code none;
  const auto received = fs::file_size(dir_ / "rotten.out", none);
  EXPECT_LT(none ? 0u : received, 1000000u);
}

TEST_F(Central, ControlRequestsAreRefusedAsReadOnly) {
  for (const auto& [method, path] : std::vector<std::pair<std::string, std::string>>{
           {"POST", "/v1/executions"},
           {"POST", "/v1/queue"},
           {"DELETE", "/v1/keys/x"},
           {"POST", "/v1/control/acquire"},
           {"PUT", "/v1/runs/" + w().chart_run},
           {"POST", "/v1/blobs/retention"},
       }) {
    auto r = central(path, {"-X", method, "-H", "Content-Type: application/json", "--data", "{}"});
    EXPECT_EQ(r.status, 405) << method << " " << path << ": " << r.body;
    EXPECT_EQ(r.headers["content-type"], "application/problem+json");
    EXPECT_EQ(r.doc()["code"], "central-read-only") << r.body;
    EXPECT_NE(r.doc()["detail"].get<std::string>().find("changes nothing"), std::string::npos);
    EXPECT_EQ(r.headers["allow"], "GET, HEAD");
  }
  auto live = central("/v1/instruments");
  EXPECT_EQ(live.status, 404);
  EXPECT_EQ(live.doc()["code"], "not-on-central");
  auto root = central("/v1").doc();
  EXPECT_EQ(root["server"], "colorlab-central");
  EXPECT_EQ(root["read_only"], true);
}

TEST_F(Central, AWrongKeyIsRefusedAsOnABench) {
  auto wrong = curl(w().central_url + "/v1/runs", {"-H", "Authorization: Bearer clk_not-a-key"}, dir_);
  EXPECT_EQ(wrong.status, 401) << wrong.body;
  EXPECT_EQ(wrong.headers["content-type"], "application/problem+json");
  EXPECT_NE(wrong.headers["www-authenticate"].find("invalid_token"), std::string::npos);
  auto on_bench = curl(w().bench_url + "/v1/runs", {"-H", "Authorization: Bearer clk_not-a-key"}, dir_);
  EXPECT_EQ(on_bench.status, 401);
  EXPECT_EQ(wrong.doc()["code"], on_bench.doc()["code"]);
  EXPECT_EQ(central("/v1/runs").status, 200) << "the right key reads";
}

}  // namespace
