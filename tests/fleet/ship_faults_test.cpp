// colorlab-ship under faults, against a real PostgreSQL 15 and a real Swift s3api on 127.0.0.1 (issue 22): the
// network cut mid-batch (socat proxies killed and restarted), the bucket answering 503 or stalling (a small Python
// proxy), wrong credentials, PostgreSQL over TLS with sslmode=verify-full — each followed by convergence with
// nothing lost or doubled — and the bench showing its lag and the agent's last error (GET /v1/shipping, `colorlab
// status`) with a real colorlabd. One process starts both servers once; a machine without them fails these tests.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/socket.h>
#include <netinet/in.h>
#include <arpa/inet.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <random>
#include <set>
#include <thread>

#include <nlohmann/json.hpp>

#include "colorlab/fleet/bench_reader.hpp"
#include "colorlab/fleet/digest.hpp"
#include "colorlab/fleet/pg.hpp"
#include "colorlab/fleet/s3.hpp"
#include "colorlab/store/sqlite.hpp"
#include "colorlab/testing/daemon.hpp"
#include "colorlab/testing/process.hpp"
#include "fleet_servers.hpp"
#include "resume_support.hpp"
#include "sim_bench.hpp"

namespace fs = std::filesystem;
using namespace colorlab;
namespace ct = colorlab::testing;
using namespace colorlab::fleet_test;
using protocol::ExecutionStatus;
using nlohmann::json;
using ct::bin_path;
using ct::run_command;
using steady = std::chrono::steady_clock;

namespace {

SharedServers& servers() {
  return shared_servers(fs::path(COLORLAB_BIN_DIR).parent_path() / "tests" / "fleet-faults-scratch", "colorlab-faults-pg");
}

int port_of(const std::string& text, const std::string& prefix) {
  auto at = text.rfind(prefix);
  if (at == std::string::npos) throw std::runtime_error("no " + prefix + " in " + text);
  return std::stoi(text.substr(at + prefix.size()));
}

// socat relaying 127.0.0.1:listen to 127.0.0.1:upstream, a child per connection. Started through setsid, so
// cut() kills the whole process group: the listener and every connection it relays, as a cable pulled would.
class Socat {
 public:
  Socat(int listen, int upstream) : listen_(listen), upstream_(upstream) { start(); }
  ~Socat() { cut(); }
  void start() {
    process_ = std::make_unique<ct::Process>(std::vector<std::string>{
        "/usr/bin/setsid", "/usr/bin/socat", "TCP-LISTEN:" + std::to_string(listen_) + ",bind=127.0.0.1,reuseaddr,fork",
        "TCP:127.0.0.1:" + std::to_string(upstream_)});
    const auto deadline = steady::now() + std::chrono::seconds(30);
    while (!accepts(listen_)) {
      if (steady::now() > deadline) throw std::runtime_error("socat did not listen on " + std::to_string(listen_));
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  void cut() {
    if (!process_) return;
    ::kill(-process_->pid(), SIGKILL);
    process_->wait(std::chrono::seconds(30));
    process_.reset();
  }

 private:
  int listen_, upstream_;
  std::unique_ptr<ct::Process> process_;
};

// tests/fleet/ship_faults_proxy.py in front of the store, misbehaving on `plan`.
class FaultProxy {
 public:
  FaultProxy(int upstream, const std::string& plan)
      : process_({"/usr/bin/python3", std::string(COLORLAB_SOURCE_DIR) + "/tests/fleet/ship_faults_proxy.py",
                  std::to_string(upstream), plan}) {
    auto line = process_.read_line(std::chrono::seconds(60));
    if (!line) throw std::runtime_error("the fault proxy did not start");
    port_ = std::stoi(*line);
  }
  ~FaultProxy() { process_.signal(SIGKILL); }
  std::string endpoint() const { return "http://127.0.0.1:" + std::to_string(port_); }

 private:
  ct::Process process_;
  int port_ = 0;
};

class ShipFaults : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string missing = missing_tools() + (ct::on_path("socat") ? "" : " socat");
    // Not a skip: a CI machine without the servers has lost a feature's tests, which must show.
    if (!missing.empty()) FAIL() << "the fleet fault tests need:" << missing << " (scripts/setup.sh installs them)";
    name_ = servers().fresh_for_current_test();
    dir_ = servers().root / name_;
  }

  ShipTarget target() const {
    auto& s = servers();
    return {s.pg->conninfo(name_), s.swift->endpoint(), name_, SwiftServer::kAccessKey, SwiftServer::kSecretKey};
  }
  int pg_port() const { return port_of(target().postgres, "port="); }
  int swift_port() const { return port_of(servers().swift->endpoint(), ":"); }

  fleet::Pg central() const { return fleet::Pg(servers().pg->conninfo(name_)); }

  static ct::RunResult ship(const fs::path& config, const std::string& command = "once") {
    return run_command({bin_path("colorlab-ship"), "--config", config.string(), command}, std::chrono::seconds(120));
  }

  std::int64_t position(const std::string& bench_id) const {
    auto r = central().query("SELECT shipped_position FROM benches WHERE id = $1", {bench_id});
    return r.rows() ? r.int64(0, 0) : 0;
  }
  std::int64_t central_runs() const { return central().query("SELECT count(*) FROM runs").int64(0, 0); }

  // Cycles until one ships nothing; every cycle must exit 0.
  static void converge(const fs::path& config) {
    for (int i = 0; i < 40; ++i) {
      auto r = ship(config);
      ASSERT_EQ(r.exit_code, 0) << r.err;
      if (json::parse(r.out)["runs_shipped"] == 0) return;
    }
    FAIL() << "40 cycles did not ship everything";
  }

  // Every run the bench ended is on central exactly once and the same (digest, status, measurements, blobs that
  // re-hash to their names), the bench's events arrived gap-free, and the position is the last end event.
  void expect_converged(const fs::path& database, const std::string& bench_id) {
    auto pg = central();
    fleet::BenchReader reader(database);
    const auto ended = reader.ended_after(0, 1000000);
    ASSERT_FALSE(ended.empty());
    const std::int64_t pos = position(bench_id);
    EXPECT_EQ(pos, ended.back().ended_event) << "something ended is not shipped";
    for (const auto& r : ended) {
      auto d = pg.query(fleet::kCentralDigestSql, {r.run_id});
      ASSERT_EQ(d.rows(), 1) << "run " << r.run_id << " missing on central";
      EXPECT_EQ(d.text(0, 0), reader.digest(r.run_id)) << "run " << r.run_id;
      EXPECT_EQ(pg.query("SELECT status FROM runs WHERE id = $1", {r.run_id}).text(0, 0), r.status);
    }
    auto runs = pg.query("SELECT count(*), count(DISTINCT id) FROM runs WHERE bench_id = $1", {bench_id});
    EXPECT_EQ(runs.int64(0, 0), static_cast<long long>(ended.size()));
    EXPECT_EQ(runs.int64(0, 1), runs.int64(0, 0));

    store::Database db(database.string(), true);
    auto bm = db.prepare("SELECT count(*) FROM measurements");
    bm.step();
    auto m = pg.query(
        "SELECT count(*), count(DISTINCT (m.run_id, m.step)) FROM measurements m JOIN runs r ON r.id = m.run_id "
        "WHERE r.bench_id = $1",
        {bench_id});
    EXPECT_EQ(m.int64(0, 0), bm.int64(0)) << "measurements lost or doubled";
    EXPECT_EQ(m.int64(0, 1), m.int64(0, 0));

    std::vector<long long> bench_seqs, central_seqs;
    auto es = db.prepare("SELECT seq FROM event_log WHERE seq <= ?1 ORDER BY seq");
    es.bind(1, pos);
    while (es.step()) bench_seqs.push_back(es.int64(0));
    auto ce = pg.query("SELECT seq FROM events WHERE bench_id = $1 ORDER BY seq", {bench_id});
    for (int i = 0; i < ce.rows(); ++i) central_seqs.push_back(ce.int64(i, 0));
    EXPECT_EQ(central_seqs, bench_seqs) << "events missing, doubled or beyond the position";

    fleet::S3Client s3(servers().swift->endpoint(), name_, "us-east-1", {SwiftServer::kAccessKey, SwiftServer::kSecretKey});
    auto blobs = pg.query(
        "SELECT DISTINCT b.sha256 FROM run_blobs b JOIN runs r ON r.id = b.run_id WHERE r.bench_id = $1", {bench_id});
    for (int i = 0; i < blobs.rows(); ++i) {
      const std::string sha = blobs.text(i, 0);
      EXPECT_EQ(fleet::sha256_hex(s3.get("sha256/" + sha)), sha);
    }
  }

  // Adds lines to the [ship] section SimBench wrote (it is the file's last table).
  static void add_ship_keys(const fs::path& config, const std::string& lines) {
    std::ofstream(config, std::ios::app) << lines;
  }

  std::string name_;
  fs::path dir_;
};

// The bench shows what waits and what the agent last said, from its own files: GET /v1/shipping and `colorlab
// status` against a real colorlabd. Runs an old daemon left running without a script end as `interrupted` when
// colorlabd opens the store and ship marked as such.
TEST_F(ShipFaults, TheBenchShowsItsLagAndTheAgentsLastError) {
  // A short state directory: colorlabd's Unix socket lives in it, and a socket path has at most 107 bytes.
  struct Short {
    fs::path dir = fs::temp_directory_path() / ("clf-" + std::to_string(::getpid()));
    ~Short() {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  } short_dir;
  fs::remove_all(short_dir.dir);
  const fs::path state = short_dir.dir / "state";
  fs::path ship_config;
  std::string left_running, old_marked;
  {
    SimBench bench(state, "bench-v", 41);
    bench.run_campaign(ExecutionStatus::finished_ok, 12, 4);
    bench.run_campaign(ExecutionStatus::finished_error, 6, 3);
    left_running = bench.run_campaign(ExecutionStatus::finished_ok, 5, 0, false);
    old_marked = bench.run_campaign(ExecutionStatus::finished_ok, 5, 0, false);
    auto t = target();
    t.access_key = "test:nobody";  // an access key the store does not know (Swift answers SignatureDoesNotMatch)
    ship_config = bench.write_config(t);
  }
  {
    // What an older colorlabd did at start-up: finalised, without an end event.
    store::Database db((state / "colorlab.db").string(), false);
    db.exec("UPDATE runs SET status = 'interrupted', finished_at = '2026-01-02T03:04:05.000Z' WHERE id = '" +
            old_marked + "'");
    db.exec("UPDATE executions SET status = 'interrupted' WHERE run_id = '" + old_marked + "'");
  }
  fs::create_directories(dir_ / "daemon");
  const auto daemon_config = ct::write_daemon_config(dir_ / "daemon", 500, 41, "\n[ship]\nbench_id = \"bench-v\"\n");
  std::unique_ptr<ct::DaemonProcess> started;
  try {
    started = std::make_unique<ct::DaemonProcess>(state, daemon_config, dir_ / "colorlabd.log");
  } catch (const std::exception& e) {
    std::ifstream log(dir_ / "colorlabd.log");
    FAIL() << e.what() << "\ncolorlabd's log:\n"
           << std::string(std::istreambuf_iterator<char>(log), {});
  }
  auto& daemon = *started;
  auto api = ct::api_for(daemon);

  json s = api.get("/v1/shipping");
  EXPECT_EQ(s["enabled"], true);
  EXPECT_EQ(s["shipped_position"], 0);
  EXPECT_EQ(s["lag"]["unshipped_runs"], 4) << s.dump() << " (two ended, two given end events at start-up)";
  EXPECT_TRUE(s["lag"]["age_s"].is_number()) << s.dump();
  EXPECT_GE(s["lag"]["age_s"].get<double>(), 0.0);
  EXPECT_TRUE(s["agent"].is_null()) << "no agent cycle yet";
  EXPECT_TRUE(s["last_error"].is_null());

  // Wrong credentials: a clear error, nothing shipped, and the bench says so.
  auto r = ship(ship_config);
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.err.find("SignatureDoesNotMatch"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("access_key_file"), std::string::npos) << r.err;
  EXPECT_EQ(central_runs(), 0);
  EXPECT_EQ(position("bench-v"), 0);
  s = api.get("/v1/shipping");
  ASSERT_TRUE(s["last_error"].is_object()) << s.dump();
  EXPECT_NE(s["last_error"]["message"].get<std::string>().find("SignatureDoesNotMatch"), std::string::npos) << s.dump();
  EXPECT_NE(s["last_error"]["hint"].get<std::string>().find("access_key_file"), std::string::npos) << s.dump();
  EXPECT_EQ(s["agent"]["ok"], false);
  EXPECT_EQ(s["lag"]["unshipped_runs"], 4);
  EXPECT_TRUE(s["agent_seen_s_ago"].is_number());
  EXPECT_EQ(s.dump().find(SwiftServer::kSecretKey), std::string::npos) << "a secret in the answer";

  auto status = run_command({bin_path("colorlab"), "--url", daemon.url(), "status"});
  ASSERT_EQ(status.exit_code, 0) << status.err;
  EXPECT_NE(status.out.find("4 ended run(s) not shipped"), std::string::npos) << status.out;
  EXPECT_NE(status.out.find("last cycle FAILED"), std::string::npos) << status.out;
  EXPECT_NE(status.out.find("SignatureDoesNotMatch"), std::string::npos) << status.out;

  // The right key: everything ships, the two runs ended at start-up as `interrupted`; the lag is gone.
  std::ofstream(state / "s3-access-key") << SwiftServer::kAccessKey << "\n";
  converge(ship_config);
  expect_converged(state / "colorlab.db", "bench-v");
  auto pg = central();
  EXPECT_EQ(pg.query("SELECT status FROM runs WHERE id = $1", {left_running}).text(0, 0), "interrupted");
  EXPECT_EQ(pg.query("SELECT status FROM runs WHERE id = $1", {old_marked}).text(0, 0), "interrupted");
  EXPECT_EQ(pg.query("SELECT count(*) FROM events WHERE bench_id = 'bench-v' AND payload::jsonb ->> 'run_id' = $1 "
                     "AND (payload::jsonb ->> 'recorded_at_open')::boolean",
                     {old_marked})
                .int64(0, 0),
            1);
  s = api.get("/v1/shipping");
  EXPECT_EQ(s["lag"]["unshipped_runs"], 0) << s.dump();
  EXPECT_EQ(s["lag"]["age_s"], 0);
  EXPECT_TRUE(s["lag"]["oldest_unshipped_run"].is_null());
  EXPECT_EQ(s["shipped_position"], position("bench-v"));
  EXPECT_EQ(s["agent"]["ok"], true);
  EXPECT_TRUE(s["agent"]["last_success_at"].is_string());
  EXPECT_TRUE(s["last_error"].is_object()) << "the last error stays, with its time, after a later success";
  status = run_command({bin_path("colorlab"), "--url", daemon.url(), "status"});
  EXPECT_NE(status.out.find("every ended run has shipped"), std::string::npos) << status.out;
  EXPECT_NE(status.out.find("last cycle ok"), std::string::npos) << status.out;
}

// The network cut at random moments of a cycle: both links (PostgreSQL and the store) go through socat, which is
// killed with every connection it relays and started again. The agent never hangs, and then converges.
TEST_F(ShipFaults, NetworkCutAtRandomMomentsConverges) {
  SimBench bench(dir_ / "bench", "bench-n", 42);
  const int pg_proxy = free_port_run(2);
  const int s3_proxy = pg_proxy + 1;
  Socat pg_link(pg_proxy, pg_port());
  Socat s3_link(s3_proxy, swift_port());
  auto t = target();
  t.postgres += " port=" + std::to_string(pg_proxy);
  t.s3_endpoint = "http://127.0.0.1:" + std::to_string(s3_proxy);
  auto config = bench.write_config(t, 3);
  for (int i = 0; i < 3; ++i) bench.run_campaign(ExecutionStatus::finished_ok, 15, 5);
  const auto t0 = steady::now();
  auto first = ship(config);
  ASSERT_EQ(first.exit_code, 0) << first.err;
  const auto cycle = std::chrono::duration_cast<std::chrono::microseconds>(steady::now() - t0).count();

  std::mt19937 rng(static_cast<unsigned>(std::random_device{}()));
  const unsigned seed = rng();
  std::cerr << "cut schedule seed " << seed << ", calibrated cycle " << cycle << " us\n";
  rng.seed(seed);
  // As the kill test: a cut after the agent finished halves the window, one that lands lets it grow back.
  long long upper = cycle;
  int cuts = 0;
  for (int attempt = 0; cuts < 6 && attempt < 200; ++attempt) {
    bench.run_campaign(attempt % 2 ? ExecutionStatus::aborted : ExecutionStatus::finished_ok, 15, 5);
    ct::Process agent({bin_path("colorlab-ship"), "--config", config.string(), "once"});
    std::this_thread::sleep_for(
        std::chrono::microseconds(upper > 0 ? std::uniform_int_distribution<long long>(0, upper - 1)(rng) : 0));
    const bool landed = agent.running();
    pg_link.cut();
    s3_link.cut();
    auto code = agent.wait(std::chrono::seconds(120));
    ASSERT_TRUE(code.has_value()) << "the agent hung after the network was cut";
    EXPECT_TRUE(*code == 0 || *code == 1) << "exit " << *code;
    if (landed) {
      ++cuts;
      upper = std::min<long long>(cycle, upper + upper / 2 + 1);
    } else {
      upper /= 2;
    }
    // With the link down a cycle fails clearly, and marks nothing.
    const auto before = position("bench-n");
    auto down = ship(config);
    EXPECT_EQ(down.exit_code, 1);
    EXPECT_NE(down.err.find("cannot connect to the central PostgreSQL"), std::string::npos) << down.err;
    EXPECT_EQ(position("bench-n"), before);
    pg_link.start();
    s3_link.start();
  }
  ASSERT_GE(cuts, 6);
  converge(config);
  expect_converged(bench.database(), "bench-n");
  EXPECT_EQ(ship(config, "verify").exit_code, 0);
}

// The store answering 503 SlowDown for a while, from the middle of a batch: each cycle that meets one stops with a
// clear error and marks nothing past its last commit; once the store answers again everything is there once.
TEST_F(ShipFaults, BucketAnswering503ConvergesOnceItRecovers) {
  SimBench bench(dir_ / "bench", "bench-5", 43);
  for (int i = 0; i < 4; ++i) bench.run_campaign(ExecutionStatus::finished_ok, 10, 5);
  // Each run: a HEAD and a PUT per blob (2 blobs): 4 requests. Five pass (the first run and one more request),
  // then eight 503s: the second run fails in this cycle and the next.
  FaultProxy proxy(swift_port(), "pass:5,503:8");
  auto t = target();
  t.s3_endpoint = proxy.endpoint();
  auto config = bench.write_config(t);
  auto r = ship(config);
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.err.find("HTTP 503 SlowDown"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the next cycle retries"), std::string::npos) << r.err;
  fleet::BenchReader reader(bench.database());
  const auto ended = reader.ended_after(0, 100);
  EXPECT_EQ(position("bench-5"), ended.front().ended_event) << "the first run committed before the 503s";
  EXPECT_EQ(central_runs(), 1);
  auto status = json::parse(std::ifstream(bench.state_dir() / "ship" / "status.json"));
  EXPECT_EQ(status["ok"], false);
  EXPECT_NE(status["last_error"]["message"].get<std::string>().find("503"), std::string::npos) << status.dump();
  int failed = 1;
  for (int i = 0; i < 10; ++i) {
    r = ship(config);
    if (r.exit_code == 0) break;
    EXPECT_EQ(r.exit_code, 1) << r.err;
    ++failed;
  }
  EXPECT_GE(failed, 2) << "eight 503s outlast one cycle";
  converge(config);
  expect_converged(bench.database(), "bench-5");
}

// A store that takes a request and never answers (the second run's first HEAD): the request ends after [ship] stall_timeout_s, the cycle says
// the store stalled, nothing is marked shipped past the last commit, and the next cycle converges.
TEST_F(ShipFaults, StallingBucketEndsTheCycleAndConverges) {
  SimBench bench(dir_ / "bench", "bench-st", 44);
  for (int i = 0; i < 3; ++i) bench.run_campaign(ExecutionStatus::finished_ok, 10, 5);
  // A HEAD that never answers: no bytes move, so the stall limit is all that ends it.
  FaultProxy proxy(swift_port(), "pass:4,stall:1");
  auto t = target();
  t.s3_endpoint = proxy.endpoint();
  auto config = bench.write_config(t);
  // Long enough that a slow but working Swift on a loaded machine is not taken for a stall before the stalled
  // request; taken out again before converging, so the default governs the rest.
  const std::string stall_key = "stall_timeout_s = 8\n";
  add_ship_keys(config, stall_key);
  auto r = ship(config);
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.err.find("stalled"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("stall_timeout_s"), std::string::npos) << r.err;
  fleet::BenchReader reader(bench.database());
  EXPECT_EQ(position("bench-st"), reader.ended_after(0, 100).front().ended_event);
  EXPECT_EQ(central_runs(), 1);
  {
    std::ifstream in(config);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    in.close();
    text.erase(text.rfind(stall_key), stall_key.size());
    std::ofstream(config, std::ios::trunc) << text;
  }
  converge(config);
  expect_converged(bench.database(), "bench-st");
}

// PostgreSQL over TLS with sslmode=verify-full against a throwaway CA made with the openssl CLI: the server is
// verified and shipping works (the database refuses connections without TLS, so it was TLS); a certificate from
// another CA and a host name the certificate does not name are refused with libpq's reason, nothing shipped.
TEST_F(ShipFaults, PostgresOverTlsVerifiesTheServer) {
  const fs::path pki = dir_ / "pki";
  fs::create_directories(pki);
  const std::string p = pki.string();
  auto sh = [](const std::string& cmd) {
    auto r = run_command({"/bin/sh", "-c", cmd}, std::chrono::seconds(60));
    if (r.exit_code != 0) throw std::runtime_error(cmd + ": " + r.err);
  };
  // The lab's CA, the server's certificate for 127.0.0.1 and localhost signed by it, and an unrelated CA.
  for (const char* ca : {"ca", "other-ca"}) {
    sh("cd " + p + " && openssl req -x509 -newkey rsa:2048 -nodes -days 2 -subj /CN=colorlab-test-" + ca +
       " -keyout " + ca + ".key -out " + ca + ".pem 2>&1");
  }
  sh("cd " + p + " && openssl req -newkey rsa:2048 -nodes -subj /CN=127.0.0.1 -keyout server.key -out server.csr 2>&1 && "
                 "printf 'subjectAltName=IP:127.0.0.1,DNS:localhost\\n' > san.ext && "
                 "openssl x509 -req -in server.csr -CA ca.pem -CAkey ca.key -CAcreateserial -days 2 -extfile san.ext "
                 "-out server.crt 2>&1");
  auto& s = servers();
  const std::string data = s.pg->psql("postgres", "SHOW data_directory");
  // The server's key belongs to the server's user, mode 0600 (PostgreSQL refuses anything looser).
  sh("install -m 600 " + p + "/server.key " + data + "/colorlab-test-server.key && install -m 644 " + p +
     "/server.crt " + data + "/colorlab-test-server.crt && chown --reference=" + data + "/PG_VERSION " + data +
     "/colorlab-test-server.key " + data + "/colorlab-test-server.crt");
  s.pg->psql("postgres", "ALTER SYSTEM SET ssl_cert_file = 'colorlab-test-server.crt'");
  s.pg->psql("postgres", "ALTER SYSTEM SET ssl_key_file = 'colorlab-test-server.key'");
  s.pg->psql("postgres", "ALTER SYSTEM SET ssl = on");
  s.pg->psql("postgres", "SELECT pg_reload_conf()");
  // This test's database only over TLS: a first pg_hba line, read on reload.
  const std::string hba = s.pg->psql("postgres", "SHOW hba_file");
  sh("sed -i '1i hostnossl " + name_ + " all all reject' " + hba);
  s.pg->psql("postgres", "SELECT pg_reload_conf()");
  struct Restore {
    PostgresServer& pg;
    std::string hba, name;
    ~Restore() {
      try {
        run_command({"/bin/sh", "-c", "sed -i '/^hostnossl " + name + " /d' " + hba});
        pg.psql("postgres", "ALTER SYSTEM RESET ssl");
        pg.psql("postgres", "SELECT pg_reload_conf()");
      } catch (...) {
      }
    }
  } restore{*s.pg, hba, name_};

  SimBench bench(dir_ / "bench", "bench-tls", 45);
  for (int i = 0; i < 2; ++i) bench.run_campaign(ExecutionStatus::finished_ok, 10, 5);
  auto t = target();
  const std::string plain = t.postgres;

  // Without TLS the database is refused: the checks below are about TLS, not some other way in.
  t.postgres = plain + " sslmode=disable";
  auto config = bench.write_config(t);
  auto r = ship(config);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("no encryption"), std::string::npos) << r.err;

  t.postgres = plain + " sslmode=verify-full sslrootcert=" + p + "/other-ca.pem";
  config = bench.write_config(t);
  r = ship(config);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("certificate verify failed"), std::string::npos) << r.err;

  // The right CA, a name the certificate does not hold (hostaddr connects, host is what is verified).
  t.postgres = plain + " sslmode=verify-full sslrootcert=" + p + "/ca.pem host=central.lab.example hostaddr=127.0.0.1";
  config = bench.write_config(t);
  r = ship(config);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("does not match host name \"central.lab.example\""), std::string::npos) << r.err;
  // The test's own look at central goes over TLS too (not verified: that is the agent's part).
  fleet::Pg look(plain + " sslmode=require");
  EXPECT_EQ(look.query("SELECT count(*) FROM pg_tables WHERE tablename IN ('runs', 'benches')").int64(0, 0), 0)
      << "the agent wrote through a refused link";

  t.postgres = plain + " sslmode=verify-full sslrootcert=" + p + "/ca.pem";
  config = bench.write_config(t);
  converge(config);
  // The test reads central without TLS's refusal: through the same verified connection string.
  fleet::Pg tls(t.postgres);
  EXPECT_EQ(tls.query("SELECT ssl::text FROM pg_stat_ssl WHERE pid = pg_backend_pid()").text(0, 0), "true");
  EXPECT_EQ(tls.query("SELECT count(*) FROM runs").int64(0, 0), 2);
}

}  // namespace
