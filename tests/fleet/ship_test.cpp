// colorlab-ship against a real PostgreSQL 15 and a real Swift s3api on 127.0.0.1 (issue 22, first part): what a
// bench ended arrives whole and once, a kill -9 at any moment converges, wrong keys ship nothing, and a row
// changed on the bench after shipping shows up as a digest mismatch. One process starts both servers once.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <cstdlib>
#include <iostream>
#include <map>
#include <random>
#include <set>
#include <thread>

#include <nlohmann/json.hpp>

#include "colorlab/fleet/bench_reader.hpp"
#include "colorlab/fleet/digest.hpp"
#include "colorlab/fleet/pg.hpp"
#include "colorlab/fleet/s3.hpp"
#include "colorlab/store/sqlite.hpp"
#include "colorlab/testing/process.hpp"
#include "fleet_servers.hpp"
#include "sim_bench.hpp"

namespace fs = std::filesystem;
using namespace colorlab;
namespace ct = colorlab::testing;
using namespace colorlab::fleet_test;
using protocol::ExecutionStatus;
using ct::bin_path;
using ct::run_command;

namespace {

SharedServers& servers() {
  return shared_servers(fs::path(COLORLAB_BIN_DIR).parent_path() / "tests" / "fleet-scratch", "colorlab-fleet-pg");
}

class Fleet : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string missing = missing_tools();
    if (!missing.empty()) {
      if (std::getenv("CI")) FAIL() << "fleet tests need:" << missing << " (scripts/setup.sh installs them)";
      GTEST_SKIP() << "needs" << missing << " (scripts/setup.sh installs them)";
    }
    name_ = servers().fresh_for_current_test();
    dir_ = servers().root / name_;
  }

  ShipTarget target() const {
    auto& s = servers();
    return {s.pg->conninfo(name_), s.swift->endpoint(), name_, SwiftServer::kAccessKey, SwiftServer::kSecretKey};
  }

  fleet::Pg central() const { return fleet::Pg(servers().pg->conninfo(name_)); }

  ct::RunResult ship(const fs::path& config, const std::string& command = "once") const {
    return run_command({bin_path("colorlab-ship"), "--config", config.string(), command}, std::chrono::seconds(120));
  }

  std::int64_t position(const std::string& bench_id) const {
    auto pg = central();
    auto r = pg.query("SELECT shipped_position FROM benches WHERE id = $1", {bench_id});
    return r.rows() ? r.int64(0, 0) : 0;
  }

  // Everything the bench ended up to central's position is there exactly once and the same; nothing later is.
  void expect_converged(SimBench& bench) {
    auto pg = central();
    fleet::BenchReader reader(bench.database());
    const std::int64_t pos = position(bench.bench_id());
    auto ended = reader.ended_after(0, 1000000);
    std::set<std::string> shipped;
    for (const auto& r : ended) {
      if (r.ended_event > pos) continue;
      shipped.insert(r.run_id);
      auto d = pg.query(fleet::kCentralDigestSql, {r.run_id});
      ASSERT_EQ(d.rows(), 1) << "run " << r.run_id << " missing on central";
      EXPECT_EQ(d.text(0, 0), reader.digest(r.run_id)) << "run " << r.run_id;
      auto st = pg.query("SELECT status FROM runs WHERE id = $1", {r.run_id});
      EXPECT_EQ(st.text(0, 0), r.status);
    }
    auto runs = pg.query("SELECT count(*), count(DISTINCT id) FROM runs WHERE bench_id = $1", {bench.bench_id()});
    EXPECT_EQ(runs.int64(0, 0), static_cast<long long>(shipped.size()));
    EXPECT_EQ(runs.int64(0, 1), runs.int64(0, 0));

    store::Database db(bench.database().string(), true);
    long long bench_measurements = 0;
    for (const auto& id : shipped) {
      auto st = db.prepare("SELECT count(*) FROM measurements WHERE run_id = ?1");
      st.bind(1, std::string_view(id));
      st.step();
      bench_measurements += st.int64(0);
    }
    auto m = pg.query(
        "SELECT count(*), count(DISTINCT (m.run_id, m.step)) FROM measurements m JOIN runs r ON r.id = m.run_id "
        "WHERE r.bench_id = $1",
        {bench.bench_id()});
    EXPECT_EQ(m.int64(0, 0), bench_measurements);
    EXPECT_EQ(m.int64(0, 1), m.int64(0, 0));

    // Events: exactly the bench's seqs up to the position, none missing, none twice, none beyond.
    std::vector<long long> bench_seqs, central_seqs;
    auto es = db.prepare("SELECT seq FROM event_log WHERE seq <= ?1 ORDER BY seq");
    es.bind(1, static_cast<std::int64_t>(pos));
    while (es.step()) bench_seqs.push_back(es.int64(0));
    auto ce = pg.query("SELECT seq FROM events WHERE bench_id = $1 ORDER BY seq", {bench.bench_id()});
    for (int i = 0; i < ce.rows(); ++i) central_seqs.push_back(ce.int64(i, 0));
    EXPECT_EQ(central_seqs, bench_seqs);
    if (!bench_seqs.empty()) {
      EXPECT_EQ(bench_seqs.front(), 1);
      EXPECT_EQ(bench_seqs.back() - bench_seqs.front() + 1, static_cast<long long>(bench_seqs.size())) << "gap on the bench";
    }

    // Every blob central references reads back from the bucket and re-hashes to its name.
    fleet::S3Client s3(servers().swift->endpoint(), name_, "us-east-1", {SwiftServer::kAccessKey, SwiftServer::kSecretKey});
    auto blobs = pg.query(
        "SELECT DISTINCT b.sha256 FROM run_blobs b JOIN runs r ON r.id = b.run_id WHERE r.bench_id = $1",
        {bench.bench_id()});
    for (int i = 0; i < blobs.rows(); ++i) {
      const std::string sha = blobs.text(i, 0);
      EXPECT_EQ(fleet::sha256_hex(s3.get("sha256/" + sha)), sha);
    }
  }

  std::string name_;
  fs::path dir_;
};

TEST_F(Fleet, ShipsEndedRunsWholeAndCentralAgrees) {
  SimBench bench(dir_ / "bench", "bench-a", 1);
  bench.run_campaign(ExecutionStatus::finished_ok, 60);
  bench.run_campaign(ExecutionStatus::finished_error, 25);
  bench.run_campaign(ExecutionStatus::aborted, 12);
  const std::string open = bench.run_campaign(ExecutionStatus::finished_ok, 20, 10, false);
  auto config = bench.write_config(target());

  auto r = ship(config);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto report = nlohmann::json::parse(r.out);
  EXPECT_EQ(report["runs_shipped"], 3);
  EXPECT_EQ(report["measurements"], 60 + 25 + 12);
  expect_converged(bench);
  auto pg = central();
  EXPECT_EQ(pg.query("SELECT count(*) FROM runs WHERE id = $1", {open}).int64(0, 0), 0) << "a running run shipped";
  auto statuses = pg.query("SELECT string_agg(status, ',' ORDER BY ended_event) FROM runs").text(0, 0);
  EXPECT_EQ(statuses, "finished_ok,finished_error,aborted");

  // Nothing new: a second cycle ships nothing and uploads nothing.
  r = ship(config);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["runs_shipped"], 0);

  // The run that was still going ends: the next cycle ships it, and the agent's note for retention follows.
  bench.finish(open, ExecutionStatus::finished_ok);
  r = ship(config);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["runs_shipped"], 1);
  expect_converged(bench);
  auto note = bench.state_dir() / "ship" / "shipped-position";
  ASSERT_TRUE(fs::exists(note));
  EXPECT_EQ(std::stoll(ct::shell_output("cat " + note.string())), position("bench-a"));
  EXPECT_EQ(ship(config, "verify").exit_code, 0);
}

TEST_F(Fleet, KillNineAtRandomMomentsConverges) {
  SimBench bench(dir_ / "bench", "bench-k", 2);
  auto config = bench.write_config(target(), 4);
  std::mt19937 rng(static_cast<unsigned>(std::random_device{}()));
  const unsigned seed = rng();
  std::cerr << "kill schedule seed " << seed << "\n";
  rng.seed(seed);
  // Calibrate: how long one cycle of 4 runs takes here, so the kills spread over all its phases (connect, blob
  // HEAD/PUT, COPY, insert, digest, commit, the position note).
  for (int i = 0; i < 4; ++i) bench.run_campaign(ExecutionStatus::finished_ok, 15, 5);
  auto t0 = std::chrono::steady_clock::now();
  auto first = ship(config);
  ASSERT_EQ(first.exit_code, 0) << first.err;
  const auto cycle = std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - t0);
  // Kill moments uniform in [0, upper). A kill that comes too late (the agent had already finished its smaller
  // batch) halves `upper`, one that lands lets it grow back towards a whole cycle: the 20 kills always come (at
  // upper = 0 the kill follows the fork at once), spread over every phase the machine's speed allows.
  long long upper = cycle.count();
  int kills = 0;
  for (int attempt = 0; kills < 20 && attempt < 400; ++attempt) {
    bench.run_campaign(attempt % 3 == 1 ? ExecutionStatus::aborted : ExecutionStatus::finished_ok, 15, 5);
    ct::Process agent({bin_path("colorlab-ship"), "--config", config.string(), "once"});
    std::this_thread::sleep_for(std::chrono::microseconds(
        upper > 0 ? std::uniform_int_distribution<long long>(0, upper - 1)(rng) : 0));
    if (agent.running()) {
      agent.signal(SIGKILL);
      ++kills;
      upper = std::min<long long>(cycle.count(), upper + upper / 2 + 1);
    } else {
      upper /= 2;
    }
    ASSERT_TRUE(agent.wait(std::chrono::seconds(60)).has_value());
  }
  ASSERT_GE(kills, 20) << "the calibrated cycle was " << cycle.count() << " us";
  // Convergence: cycles until nothing is left, each a clean exit.
  for (int i = 0; i < 40; ++i) {
    auto r = ship(config);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    if (nlohmann::json::parse(r.out)["runs_shipped"] == 0) break;
  }
  fleet::BenchReader reader(bench.database());
  auto ended = reader.ended_after(0, 1000000);
  ASSERT_FALSE(ended.empty());
  EXPECT_EQ(position("bench-k"), ended.back().ended_event);
  expect_converged(bench);
  EXPECT_EQ(ship(config, "verify").exit_code, 0);
}

TEST_F(Fleet, WrongCredentialsShipNothingAndSaySo) {
  SimBench bench(dir_ / "bench", "bench-w", 3);
  bench.run_campaign(ExecutionStatus::finished_ok, 30, 5);
  auto t = target();
  t.secret_key = "not-the-secret-0123456789";
  auto config = bench.write_config(t);
  auto r = ship(config);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("SignatureDoesNotMatch"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("secret_key_file"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find(t.secret_key), std::string::npos) << "the secret was printed";
  EXPECT_EQ(position("bench-w"), 0);
  EXPECT_EQ(central().query("SELECT count(*) FROM runs").int64(0, 0), 0);

  // A wrong PostgreSQL login is as clear, and names no secret either.
  t = target();
  t.postgres += " user=nobody_here";
  config = bench.write_config(t);
  r = ship(config);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("cannot connect to the central PostgreSQL"), std::string::npos) << r.err;
}

TEST_F(Fleet, MeasurementAlteredAfterShippingIsDetected) {
  SimBench bench(dir_ / "bench", "bench-d", 4);
  const std::string first = bench.run_campaign(ExecutionStatus::finished_ok, 40);
  bench.run_campaign(ExecutionStatus::finished_ok, 40);
  auto config = bench.write_config(target());
  ASSERT_EQ(ship(config).exit_code, 0);
  const auto shipped = position("bench-d");
  {
    store::Database db(bench.database().string(), false);
    db.exec("UPDATE measurements SET value = value * (1 + 1e-12) WHERE run_id = '" + first + "' AND step = 'patch-7'");
  }
  auto r = ship(config, "verify");
  EXPECT_EQ(r.exit_code, 3) << r.out << r.err;
  auto out = nlohmann::json::parse(r.out);
  ASSERT_EQ(out["divergences"].size(), 1u);
  EXPECT_EQ(out["divergences"][0]["run_id"], first);
  EXPECT_EQ(central().query("SELECT count(*) FROM ship_problems WHERE run_id = $1", {first}).int64(0, 0), 1);

  // Shipping the same run again (central's position set back, as after a bench restored from an old snapshot):
  // ON CONFLICT DO NOTHING keeps central's rows, the digest sees the difference, the position stays put.
  central().query("UPDATE benches SET shipped_position = 0 WHERE id = $1", {"bench-d"});
  r = ship(config);
  EXPECT_EQ(r.exit_code, 3) << r.out << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["divergences"][0]["run_id"], first);
  EXPECT_EQ(position("bench-d"), 0);
  EXPECT_NE(central().query("SELECT last_error FROM benches WHERE id = $1", {"bench-d"}).text(0, 0).find(first),
            std::string::npos);
  (void)shipped;
}

TEST_F(Fleet, CentralSchemaOfAnotherVersionIsRefusedWithWhatToUpgrade) {
  SimBench bench(dir_ / "bench", "bench-s", 5);
  bench.run_campaign(ExecutionStatus::finished_ok, 5, 0);
  auto config = bench.write_config(target());
  auto r = ship(config, "central-init");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto pg = central();
  EXPECT_EQ(pg.query("SELECT string_agg(version::text, ',' ORDER BY version) FROM schema_migrations").text(0, 0), "1,2");

  pg.exec("INSERT INTO schema_migrations (version) VALUES (3)");
  r = ship(config);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("upgrade colorlab on this bench"), std::string::npos) << r.err;

  // An older central: version 1's tables without this build's migration 2.
  pg.exec("DELETE FROM schema_migrations WHERE version > 1");
  r = ship(config);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("upgrade the central schema"), std::string::npos) << r.err;
  EXPECT_EQ(pg.query("SELECT count(*) FROM runs").int64(0, 0), 0);
}

TEST_F(Fleet, PostgresStoppedInImmediateModeMidCycleConverges) {
  SimBench bench(dir_ / "bench", "bench-p", 6);
  for (int i = 0; i < 6; ++i) bench.run_campaign(ExecutionStatus::finished_ok, 15, 5);
  auto config = bench.write_config(target(), 2);
  ASSERT_EQ(ship(config).exit_code, 0);  // central set up, two runs in
  for (int i = 0; i < 3; ++i) bench.run_campaign(ExecutionStatus::aborted, 15, 5);
  // The server goes away without a checkpoint while (or before) the agent ships: crash recovery on restart.
  ct::Process agent({bin_path("colorlab-ship"), "--config", config.string(), "once"});
  servers().pg->stop_immediate();
  auto code = agent.wait(std::chrono::seconds(120));
  ASSERT_TRUE(code.has_value()) << "the agent hung with PostgreSQL gone";
  EXPECT_TRUE(*code == 0 || *code == 1) << "exit " << *code;
  servers().pg->start();
  for (int i = 0; i < 10; ++i) {
    auto r = ship(config);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    if (nlohmann::json::parse(r.out)["runs_shipped"] == 0) break;
  }
  fleet::BenchReader reader(bench.database());
  EXPECT_EQ(position("bench-p"), reader.ended_after(0, 1000).back().ended_event);
  expect_converged(bench);
}

}  // namespace
