// Three simulated benches on one machine shipping into one catalog (issue 22, the first test): three colorlabd,
// each on its own simulated lab whose GigE Vision camera serves its own loopback address (127.0.0.2, .3, .4 in the
// test's private network namespace: three_benches_loopback.hpp), run a frame-average on that camera and a
// chart-read at the same time, while three colorlab-ship agents ship into ONE PostgreSQL and ONE bucket; each
// agent ships its bench's first run while the bench's second campaign is still going (held paused until central
// has the first). On central: every run's digest equals its bench's, every table's rows equal its distinct ids
// (and the benches' own counts), each bench's events arrive without a gap, and every object under sha256/ in the
// bucket re-hashes to its name. Fails, not skips, without PostgreSQL 15 or Swift.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <iostream>
#include <map>
#include <regex>
#include <set>
#include <thread>

#include <nlohmann/json.hpp>

#include "colorlab/client/api_client.hpp"
#include "colorlab/fleet/bench_reader.hpp"
#include "colorlab/fleet/digest.hpp"
#include "colorlab/fleet/pg.hpp"
#include "colorlab/fleet/s3.hpp"
#include "colorlab/protocol/states.hpp"
#include "colorlab/store/sqlite.hpp"
#include "colorlab/testing/daemon.hpp"
#include "colorlab/testing/process.hpp"
#include "fleet_servers.hpp"
#include "resume_support.hpp"
#include "sim_bench.hpp"
#include "three_benches_loopback.hpp"

namespace fs = std::filesystem;
using namespace colorlab;
namespace ct = colorlab::testing;
using namespace colorlab::fleet_test;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

std::string g_loopback_error;
const std::vector<std::string> kAddresses = {"127.0.0.2", "127.0.0.3", "127.0.0.4"};

// Bounds on waits, there only to turn a hang into a message: a campaign here takes seconds of simulated time at
// time scale 500, a shipping cycle well under a second; the machine may be shared with a whole team's builds.
constexpr auto kCampaignBound = std::chrono::seconds(180);
constexpr auto kShipBound = std::chrono::seconds(180);

SharedServers& servers() {
  return shared_servers(fs::path(COLORLAB_BIN_DIR).parent_path() / "tests" / "fleet-three-scratch", "colorlab-3b-pg");
}

struct Bench {
  std::string id, address, serial;
  fs::path dir;
  std::unique_ptr<ct::DaemonProcess> daemon;
  std::unique_ptr<client::ApiClient> api;
  std::unique_ptr<ct::Process> agent;
  fs::path ship_config;
  std::string frame_execution, frame_run, chart_execution, chart_run;
  bool chart_paused = false;
};

void start_bench(Bench& b, int seed, const ShipTarget& t) {
  fs::create_directories(b.dir);
  // The DSLR is left out so the frame-average has one camera to use: the bench's own GigE Vision fake.
  std::ofstream(b.dir / "lab.toml") << "[genicam]\naddress = \"" << b.address << "\"\nserial = \"" << b.serial
                                    << "\"\nsize = [128, 96]\n[dslr]\nenabled = false\n";
  std::ofstream(b.dir / "colorlabd.toml") << "[simulator]\nenabled = true\ntime_scale = 500\nseed = " << seed
                                          << "\nconfig = \"lab.toml\"\n";
  b.daemon = std::make_unique<ct::DaemonProcess>(b.dir / "state", b.dir / "colorlabd.toml", b.dir / "colorlabd.log");
  b.api = std::make_unique<client::ApiClient>(ct::api_for(*b.daemon));

  std::ofstream(b.dir / "s3-access-key") << t.access_key << "\n";
  std::ofstream(b.dir / "s3-secret-key") << t.secret_key << "\n";
  b.ship_config = b.dir / "ship.toml";
  std::ofstream(b.ship_config) << "state_dir = \"" << (b.dir / "state").string() << "\"\n[ship]\nbench_id = \"" << b.id
                               << "\"\npostgres = \"" << t.postgres << "\"\ns3_endpoint = \"" << t.s3_endpoint
                               << "\"\nbucket = \"" << t.bucket << "\"\nregion = \"us-east-1\"\n"
                               << "access_key_file = \"s3-access-key\"\nsecret_key_file = \"s3-secret-key\"\n"
                               << "interval_s = 0.3\n";
}

json instrument(const Bench& b, const std::string& id) {
  const json all = b.api->get("/v1/instruments");  // held: a range over a temporary's member would dangle
  for (const auto& i : all["items"]) {
    if (i.value("id", std::string()) == id) return i;
  }
  return json::object();
}

std::string status_of(const Bench& b, const std::string& execution) {
  return b.api->get("/v1/executions/" + execution).value("status", std::string());
}

bool terminal(const std::string& status) {
  auto s = protocol::execution_status_from_string(status);
  return s && protocol::is_terminal(*s);
}

// Polls `done` every 50 ms until it holds or `bound` passes; false on timeout.
template <class F>
bool wait_until(F done, std::chrono::seconds bound) {
  const auto deadline = Clock::now() + bound;
  while (Clock::now() < deadline) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return done();
}

// Counts on central, 0 while the first agent has not yet created the schema.
std::int64_t central_count(const std::string& conninfo, const std::string& sql, const std::string& arg) {
  try {
    fleet::Pg pg(conninfo);
    return pg.query(sql, {arg}).int64(0, 0);
  } catch (const std::exception&) {
    return 0;
  }
}

// The bucket's keys under sha256/, listed by curl (an independent S3 client, SigV4-signed). The access key holds a
// colon, which curl's --user would split at, so the keys go in a netrc file. curl 7.88 signs the query string as
// written, so it is written in SigV4's canonical form (parameters sorted, '/' encoded) or Swift answers 403.
std::vector<std::string> list_blob_keys(const std::string& endpoint, const std::string& bucket, const fs::path& dir) {
  const fs::path netrc = dir / "netrc";
  std::ofstream(netrc) << "machine 127.0.0.1 login " << SwiftServer::kAccessKey << " password "
                       << SwiftServer::kSecretKey << "\n";
  auto r = ct::run_command({"/usr/bin/curl", "-sS", "-f", "--netrc-file", netrc.string(), "--aws-sigv4",
                            "aws:amz:us-east-1:s3", "-H", "x-amz-content-sha256: " + fleet::sha256_hex(""),
                            endpoint + "/" + bucket + "?max-keys=1000&prefix=sha256%2F"},
                           std::chrono::seconds(60));
  EXPECT_EQ(r.exit_code, 0) << "listing the bucket with curl: " << r.err << r.out;
  EXPECT_EQ(r.out.find("<IsTruncated>true</IsTruncated>"), std::string::npos)
      << "the listing was cut at 1000 keys; this test makes far fewer blobs";
  std::vector<std::string> keys;
  static const std::regex key("<Key>([^<]*)</Key>");
  for (std::sregex_iterator i(r.out.begin(), r.out.end(), key), end; i != end; ++i) keys.push_back((*i)[1].str());
  return keys;
}

std::int64_t bench_count(store::Database& db, const std::string& sql, const std::string& run_id) {
  auto st = db.prepare(sql);
  st.bind(1, std::string_view(run_id));
  st.step();
  return st.int64(0);
}

TEST(ThreeBenches, CampaignsAtOnceShipIntoOneCatalog) {
  ASSERT_TRUE(g_loopback_error.empty()) << g_loopback_error;
  const std::string missing = missing_tools();
  ASSERT_TRUE(missing.empty()) << "the fleet tests need:" << missing << " (scripts/setup.sh installs them)";
  const auto t0 = Clock::now();
  auto& s = servers();
  const std::string name = s.fresh_for_current_test();
  const ShipTarget target{s.pg->conninfo(name), s.swift->endpoint(), name, SwiftServer::kAccessKey,
                          SwiftServer::kSecretKey};
  const auto t1 = Clock::now();

  // The benches' state directories in the temporary directory: a daemon's Unix socket path must stay under
  // 108 bytes, which the build tree of a deep checkout would exceed. Removed however the test ends.
  struct Scratch {
    fs::path path = fs::temp_directory_path() / ("colorlab-3b-" + std::to_string(::getpid()));
    ~Scratch() {
      std::error_code ec;
      fs::remove_all(path, ec);
    }
  } scratch;
  std::vector<Bench> benches(3);
  for (int i = 0; i < 3; ++i) {
    auto& b = benches[static_cast<std::size_t>(i)];
    b.id = "bench-" + std::to_string(i + 1);
    b.address = kAddresses[static_cast<std::size_t>(i)];
    b.serial = "CLGVBENCH" + std::to_string(i + 1);
    b.dir = scratch.path / b.id;
    ASSERT_NO_THROW(start_bench(b, 40 + i, target)) << b.id << "'s colorlabd.log:\n"
                                                    << read_all(b.dir / "colorlabd.log");
  }
  // Each daemon has its own camera, not one absent for want of an address.
  for (auto& b : benches) {
    json cam;
    // The daemon connects its instruments after it starts serving: wait for the camera to be ready or absent.
    wait_until([&] { cam = instrument(b, "genicam"); return cam.value("state", std::string()) == "ready" || cam.value("state", std::string()) == "absent"; },
               kCampaignBound);
    ASSERT_FALSE(cam.empty()) << b.id << " lists no genicam instrument: " << b.api->get("/v1/instruments").dump();
    ASSERT_NE(cam.value("state", std::string()), "absent") << b.id << "'s GigE camera on " << b.address << ": " << cam.dump();
    EXPECT_EQ(cam.value("serial", std::string()), b.serial) << b.id << " talks to another bench's camera: " << cam.dump();
  }

  for (auto& b : benches) {
    b.agent = std::make_unique<ct::Process>(
        std::vector<std::string>{ct::bin_path("colorlab-ship"), "--config", b.ship_config.string(), "run"},
        b.dir / "ship.log");
  }

  // First campaign, on all three benches at once: a frame-average on the bench's GigE camera (measurements and
  // three kept frames: the average, the raw frame, a preview).
  for (auto& b : benches) {
    auto e = b.api->post("/v1/executions", {{"campaign", "frame-average"}, {"params", {{"frames", 4}}}});
    b.frame_execution = e["id"].get<std::string>();
    b.frame_run = e["run_id"].get<std::string>();
  }
  for (auto& b : benches) {
    ASSERT_TRUE(wait_until([&] { return terminal(status_of(b, b.frame_execution)); }, kCampaignBound))
        << b.id << "'s frame-average did not end within " << kCampaignBound.count() << " s; see "
        << (b.dir / "colorlabd.log");
    ASSERT_EQ(status_of(b, b.frame_execution), "finished_ok") << b.id;
  }

  // Second campaign, again on all three: a chart-read, held paused at its first safe point until central has the
  // bench's frame-average, so every agent commits while a campaign is going on its bench.
  for (auto& b : benches) {
    auto e = b.api->post("/v1/executions", {{"campaign", "chart-read"}, {"params", {{"chart", "cc24"}}}});
    b.chart_execution = e["id"].get<std::string>();
    b.chart_run = e["run_id"].get<std::string>();
    try {
      b.api->post("/v1/executions/" + b.chart_execution + "/pause", json::object());
      b.chart_paused = true;
    } catch (const client::ApiError& e) {
      // 409: it ended before the request came (a very fast machine); the overlap is then not shown for it.
      std::cerr << b.id << ": the chart-read could not be paused: " << e.what() << "\n";
    }
  }
  for (auto& b : benches) {
    if (!b.chart_paused) continue;
    std::string st;
    ASSERT_TRUE(wait_until([&] { st = status_of(b, b.chart_execution); return st == "paused" || terminal(st); },
                           kCampaignBound))
        << b.id << "'s chart-read neither paused nor ended within " << kCampaignBound.count() << " s: " << st;
    const bool first_on_central = wait_until(
        [&] { return central_count(target.postgres, "SELECT count(*) FROM runs WHERE id = $1", b.frame_run) == 1; },
        kShipBound);
    ASSERT_TRUE(first_on_central) << b.id << "'s agent did not ship its frame-average within " << kShipBound.count()
                                  << " s while the chart-read was " << st << ": see " << (b.dir / "ship.log");
    if (st == "paused") b.api->post("/v1/executions/" + b.chart_execution + "/resume", json::object());
  }
  for (auto& b : benches) {
    ASSERT_TRUE(wait_until([&] { return terminal(status_of(b, b.chart_execution)); }, kCampaignBound))
        << b.id << "'s chart-read did not end within " << kCampaignBound.count() << " s";
    ASSERT_EQ(status_of(b, b.chart_execution), "finished_ok") << b.id;
  }
  const auto t2 = Clock::now();

  // The agents catch up with everything the benches ended; then they and the daemons stop, and central is read.
  std::map<std::string, std::int64_t> last_end;
  for (auto& b : benches) {
    fleet::BenchReader reader(b.dir / "state" / "colorlab.db");
    for (const auto& r : reader.ended_after(0, 1000000)) last_end[b.id] = std::max(last_end[b.id], r.ended_event);
    ASSERT_TRUE(wait_until(
        [&] {
          return central_count(target.postgres,
                               "SELECT count(*) FROM benches WHERE id = $1 AND shipped_position >= " +
                                   std::to_string(last_end[b.id]),
                               b.id) == 1;
        },
        kShipBound))
        << b.id << "'s agent did not reach event " << last_end[b.id] << " within " << kShipBound.count()
        << " s: see " << (b.dir / "ship.log");
  }
  for (auto& b : benches) {
    b.agent->signal(SIGTERM);
    EXPECT_EQ(b.agent->wait(std::chrono::seconds(60)), 0) << b.id << "'s agent: " << read_all(b.dir / "ship.log");
    EXPECT_EQ(b.daemon->terminate(), 0) << b.id;
  }
  const auto t3 = Clock::now();

  fleet::Pg pg(target.postgres);
  std::set<std::string> all_runs;
  for (auto& b : benches) {
    SCOPED_TRACE(b.id);
    fleet::BenchReader reader(b.dir / "state" / "colorlab.db");
    store::Database db((b.dir / "state" / "colorlab.db").string(), true);
    const std::int64_t pos = pg.query("SELECT shipped_position FROM benches WHERE id = $1", {b.id}).int64(0, 0);

    // Every run the bench ended is on central with the bench's digest; central holds no other run of the bench.
    std::set<std::string> ended;
    std::int64_t measurements = 0, run_blobs = 0, executions = 0;
    for (const auto& r : reader.ended_after(0, 1000000)) {
      ASSERT_LE(r.ended_event, pos) << "run " << r.run_id << " ended after the shipped position";
      ended.insert(r.run_id);
      all_runs.insert(r.run_id);
      auto d = pg.query(fleet::kCentralDigestSql, {r.run_id});
      ASSERT_EQ(d.rows(), 1) << "run " << r.run_id << " is missing on central";
      EXPECT_EQ(d.text(0, 0), reader.digest(r.run_id)) << "run " << r.run_id << "'s digest differs";
      measurements += bench_count(db, "SELECT count(*) FROM measurements WHERE run_id = ?1", r.run_id);
      run_blobs += bench_count(db, "SELECT count(*) FROM run_blobs WHERE run_id = ?1", r.run_id);
      executions += bench_count(db, "SELECT count(*) FROM executions WHERE run_id = ?1", r.run_id);
    }
    EXPECT_EQ(ended, (std::set<std::string>{b.frame_run, b.chart_run}));
    auto central_runs = pg.query("SELECT id FROM runs WHERE bench_id = $1", {b.id});
    std::set<std::string> on_central;
    for (int i = 0; i < central_runs.rows(); ++i) on_central.insert(central_runs.text(i, 0));
    EXPECT_EQ(on_central, ended);
    EXPECT_GT(measurements, 0);
    EXPECT_GT(run_blobs, 0) << "the frame-average kept no frame";

    // The bench's rows arrived once each: central's counts are the bench's (a doubled row would exceed them).
    auto per_bench = [&](const std::string& table) {
      return pg.query("SELECT count(*) FROM " + table + " t JOIN runs r ON r.id = t.run_id WHERE r.bench_id = $1",
                      {b.id})
          .int64(0, 0);
    };
    EXPECT_EQ(per_bench("measurements"), measurements);
    EXPECT_EQ(per_bench("run_blobs"), run_blobs);
    EXPECT_EQ(per_bench("executions"), executions);

    // Events: exactly the bench's, 1 .. the shipped position, none missing, none twice.
    std::vector<std::pair<std::int64_t, std::string>> bench_events, central_events;
    auto es = db.prepare("SELECT seq, topic FROM event_log WHERE seq <= ?1 ORDER BY seq");
    es.bind(1, pos);
    while (es.step()) bench_events.emplace_back(es.int64(0), std::string(es.text(1)));
    auto ce = pg.query("SELECT seq, topic FROM events WHERE bench_id = $1 ORDER BY seq", {b.id});
    for (int i = 0; i < ce.rows(); ++i) central_events.emplace_back(ce.int64(i, 0), ce.text(i, 1));
    ASSERT_FALSE(central_events.empty());
    for (std::size_t i = 0; i < central_events.size(); ++i) {
      ASSERT_EQ(central_events[i].first, static_cast<std::int64_t>(i) + 1) << "a gap in the events before this seq";
    }
    EXPECT_EQ(central_events.back().first, pos) << "central's events stop short of the shipped position";
    EXPECT_EQ(central_events, bench_events);
  }

  // Across the catalog: every table's rows equal its distinct global ids, and the runs are the benches' six.
  const std::vector<std::pair<std::string, std::string>> keys = {
      {"runs", "id"},
      {"executions", "id"},
      {"measurements", "(run_id, step)"},
      {"blobs", "sha256"},
      {"run_blobs", "(run_id, name)"},
      {"events", "(bench_id, seq)"},
      {"benches", "id"},
  };
  for (const auto& [table, key] : keys) {
    auto c = pg.query("SELECT count(*), count(DISTINCT " + key + ") FROM " + table);
    EXPECT_EQ(c.int64(0, 0), c.int64(0, 1)) << table << ": rows differ from distinct " << key;
  }
  EXPECT_EQ(pg.query("SELECT count(*) FROM runs").int64(0, 0), static_cast<std::int64_t>(all_runs.size()));
  EXPECT_EQ(all_runs.size(), 6u);
  EXPECT_EQ(pg.query("SELECT count(*) FROM benches").int64(0, 0), 3);
  EXPECT_EQ(pg.query("SELECT count(*) FROM ship_problems").int64(0, 0), 0) << "an agent reported a problem";

  // The bucket: every object under sha256/ re-hashes to its name, and they are exactly the blobs central lists.
  std::set<std::string> listed, referenced;
  fleet::S3Client s3(target.s3_endpoint, target.bucket, "us-east-1", {target.access_key, target.secret_key});
  for (const auto& key : list_blob_keys(target.s3_endpoint, target.bucket, scratch.path)) {
    ASSERT_EQ(key.rfind("sha256/", 0), 0u) << key;
    const std::string hex = key.substr(7);
    EXPECT_EQ(fleet::sha256_hex(s3.get(key)), hex) << "object " << key << " does not hash to its name";
    listed.insert(hex);
  }
  auto blobs = pg.query("SELECT sha256 FROM blobs");
  for (int i = 0; i < blobs.rows(); ++i) referenced.insert(blobs.text(i, 0));
  EXPECT_FALSE(listed.empty());
  EXPECT_EQ(listed, referenced);

  auto sec = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
  std::cerr << "three benches: servers " << sec(t0, t1) << " s, campaigns (shipping alongside) " << sec(t1, t2)
            << " s, catching up and stopping " << sec(t2, t3) << " s, checks " << sec(t3, Clock::now()) << " s\n";
}

}  // namespace

int main(int argc, char** argv) {
  // Before gtest or anything else starts a thread.
  g_loopback_error = enter_private_loopback(kAddresses);
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
