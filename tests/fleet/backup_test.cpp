// `colorlab backup` / `colorlab restore` against a real PostgreSQL 15 and a real Swift s3api on 127.0.0.1
// (issue 22, "Backups of one bench" and "Nothing lost by the bench's own housekeeping"): a snapshot taken while
// a writer commits at full rate restores into a colorlabd that serves the same runs; a bench restored from an
// older snapshot ships again in a new epoch with no mismatch stuck; a full or failing disk leaves no half
// snapshot, on the disk or in the bucket. One process starts both servers once.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <thread>

#include <nlohmann/json.hpp>

#include "colorlab/fleet/backup.hpp"
#include "colorlab/fleet/bench_reader.hpp"
#include "colorlab/fleet/digest.hpp"
#include "colorlab/fleet/pg.hpp"
#include "colorlab/fleet/s3.hpp"
#include "colorlab/store/blob_store.hpp"
#include "colorlab/store/sqlite.hpp"
#include "colorlab/testing/process.hpp"
#include "colorlab/testing/temp_dir.hpp"
#include "fleet_servers.hpp"
#include "scoped_env.hpp"
#include "resume_support.hpp"
#include "sim_bench.hpp"

namespace fs = std::filesystem;
using namespace colorlab;
namespace ct = colorlab::testing;
using namespace colorlab::fleet_test;
using protocol::ExecutionStatus;
using nlohmann::json;

namespace {

SharedServers& servers() {
  return shared_servers(fs::path(COLORLAB_BIN_DIR).parent_path() / "tests" / "fleet-backup-scratch", "colorlab-backup-pg");
}

std::int64_t sql_int(store::Database& db, const std::string& sql) {
  auto st = db.prepare(sql);
  return st.step() ? st.int64(0) : -1;
}

class Backup : public ::testing::Test {
 protected:
  void SetUp() override {
    // As the other fleet tests: a machine without the servers fails here (scripts/setup.sh installs them).
    const std::string missing = missing_tools();
    ASSERT_TRUE(missing.empty()) << "the backup tests need:" << missing << " (scripts/setup.sh installs them)";
    name_ = servers().fresh_for_current_test();
    dir_ = servers().root / name_;
  }

  ShipTarget target() const {
    auto& s = servers();
    return {s.pg->conninfo(name_), s.swift->endpoint(), name_, SwiftServer::kAccessKey, SwiftServer::kSecretKey};
  }
  fleet::Pg central() const { return fleet::Pg(servers().pg->conninfo(name_)); }
  fleet::S3Client bucket() const {
    return fleet::S3Client(servers().swift->endpoint(), name_, "us-east-1", {SwiftServer::kAccessKey, SwiftServer::kSecretKey});
  }

  // Through `colorlab`, the command a lab types (it runs colorlab-ship).
  static ct::RunResult colorlab(const std::vector<std::string>& args) {
    std::vector<std::string> argv{ct::bin_path("colorlab")};
    argv.insert(argv.end(), args.begin(), args.end());
    return ct::run_command(argv, std::chrono::seconds(180));
  }
  static ct::RunResult ship(const fs::path& config, const std::string& command = "once") {
    return ct::run_command({ct::bin_path("colorlab-ship"), "--config", config.string(), command}, std::chrono::seconds(120));
  }
  // A copy of the bench's TOML aimed at another state directory (the restored one).
  static fs::path config_for(const fs::path& config, const fs::path& state_dir) {
    const fs::path out = state_dir.parent_path() / (state_dir.filename().string() + ".toml");
    std::string text = ct::shell_output("cat " + config.string());
    const auto eol = text.find('\n');
    text = "state_dir = \"" + state_dir.string() + "\"" + text.substr(eol);
    // The key files are named relative to the TOML: name them absolutely.
    for (const char* k : {"s3-access-key", "s3-secret-key"}) {
      const std::string rel = std::string("\"") + k + "\"";
      text.replace(text.find(rel), rel.size(), "\"" + (config.parent_path() / k).string() + "\"");
    }
    std::ofstream(out) << text;
    return out;
  }

  std::int64_t position(const std::string& bench_id) const {
    auto r = central().query("SELECT shipped_position FROM benches WHERE id = $1", {bench_id});
    return r.rows() ? r.int64(0, 0) : 0;
  }

  std::string name_;
  fs::path dir_;
};

TEST_F(Backup, SnapshotUnderLoadRestoresIntoADaemonServingTheSameRuns) {
  SimBench bench(dir_ / "bench", "bench-l", 11);
  for (int i = 0; i < 3; ++i) bench.run_campaign(ExecutionStatus::finished_ok, 20, 4);
  const auto config = bench.write_config(target());

  // A writer committing campaigns back to back (each step its own durable transaction, frames every 4th step)
  // for the whole backup: started before it, stopped only after it returned.
  std::atomic<bool> stop{false};
  std::atomic<int> steps{0};
  std::atomic<int> runs_written{0};
  std::thread writer([&] {
    while (!stop) {
      bench.run_campaign(ExecutionStatus::finished_ok, 20, 4);
      steps += 20;
      ++runs_written;
    }
  });
  while (runs_written == 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));  // the writer is going
  const int steps_before = steps;
  auto r = colorlab({"backup", "--config", config.string()});
  const int steps_during = steps - steps_before;
  stop = true;
  writer.join();
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  std::cerr << "steps committed by the writer while the backup ran: about " << steps_during << "\n";
  const json report = json::parse(r.out);
  EXPECT_TRUE(report["blobs_missing"].empty());
  EXPECT_TRUE(fs::is_empty(bench.state_dir() / "backup")) << "the local snapshot outlived its upload";

  // The bucket: the index names it, its manifest describes the object, and the object hashes to the manifest.
  auto s3 = bucket();
  const json index = json::parse(s3.get("backups/bench-l/index.json"));
  ASSERT_EQ(index["snapshots"].size(), 1u);
  EXPECT_EQ(index["snapshots"][0]["name"], report["name"]);
  const std::string prefix = "backups/bench-l/" + report["name"].get<std::string>() + "/";
  const json manifest = json::parse(s3.get(prefix + "manifest.json"));
  EXPECT_EQ(fleet::sha256_hex(s3.get(prefix + "colorlab.db")), manifest["database"]["sha256"]);
  EXPECT_EQ(manifest["last_event"], report["last_event"]);

  // Restored through `colorlab restore`: a new state directory, the database whole, every blob in place. A short
  // path: colorlabd's Unix socket lives in it, and a socket's path has at most 107 bytes.
  ct::TempDir short_dir;
  const fs::path restored = short_dir / "restored";
  r = colorlab({"restore", "--config", config.string(), "--into", restored.string()});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const json rr = json::parse(r.out);
  EXPECT_EQ(rr["epoch"], 1);
  EXPECT_EQ(rr["next_event"], (std::int64_t{1} << fleet::kEpochShift) + 1);
  EXPECT_TRUE(rr["blobs_missing"].empty());
  EXPECT_EQ(ct::integrity_check(restored), "ok");

  // The snapshot is one moment of the bench: every run it holds as ended is the bench's run exactly (digest);
  // a run the writer had under way holds a prefix of its steps; nothing the bench lacks.
  std::map<std::string, std::string> restored_status;
  {
    store::Database db((restored / "colorlab.db").string(), true);
    EXPECT_EQ(sql_int(db, "SELECT max(seq) FROM event_log"), report["last_event"].get<std::int64_t>());
    auto st = db.prepare("SELECT id, status FROM runs");
    while (st.step()) restored_status[st.text(0)] = st.text(1);
    // Every blob the snapshot references is there, under its own hash.
    store::BlobStore files(restored / "blobs");
    auto b = db.prepare("SELECT sha256 FROM blobs");
    int blobs = 0;
    while (b.step()) {
      EXPECT_EQ(store::BlobStore::hash_file(files.path_of(b.text(0))), b.text(0));
      ++blobs;
    }
    EXPECT_GT(blobs, 0);
  }
  ASSERT_GE(restored_status.size(), 3u);
  fleet::BenchReader source(bench.database()), copy(restored / "colorlab.db");
  int ended = 0;
  for (const auto& [id, status] : restored_status) {
    if (status == "finished_ok") {
      EXPECT_EQ(copy.digest(id), source.digest(id)) << "run " << id;
      ++ended;
    } else {
      // The one the writer was in when the snapshot was taken: a run is created 'waiting' and set 'running' in
      // the next commit, and the snapshot's moment can fall between the two.
      EXPECT_TRUE(status == "running" || status == "waiting") << "run " << id << ": " << status;
    }
  }
  EXPECT_GE(ended, 3);
  std::cerr << "snapshot: " << restored_status.size() << " runs, " << ended << " ended, last event "
            << report["last_event"] << ", " << report["database_bytes"] << " bytes\n";

  // A fresh colorlabd on the restored state directory serves those runs.
  {
    auto daemon_config = ct::write_daemon_config(dir_, 500, 3);
    std::unique_ptr<ct::DaemonProcess> started;
    try {
      started = std::make_unique<ct::DaemonProcess>(restored, daemon_config, dir_ / "restored-colorlabd.log");
    } catch (const std::exception& e) {
      FAIL() << e.what() << "\n"
             << ct::shell_output("tail -30 " + (dir_ / "restored-colorlabd.log").string());
    }
    auto& daemon = *started;
    auto api = ct::api_for(daemon);
    std::map<std::string, std::string> served;
    std::string cursor;
    for (int page = 0; page < 100; ++page) {
      const json doc = api.get("/v1/runs?limit=50" + (cursor.empty() ? std::string() : "&cursor=" + cursor));
      for (const auto& item : doc["items"]) served[item["id"].get<std::string>()] = item["status"].get<std::string>();
      if (doc["next_cursor"].is_null()) break;
      cursor = doc["next_cursor"].get<std::string>();
    }
    ASSERT_EQ(served.size(), restored_status.size());
    for (const auto& [id, status] : restored_status) {
      ASSERT_TRUE(served.count(id)) << "run " << id << " not served";
      // The run the writer had under way was left unfinished without a script: colorlabd marks it interrupted.
      if (status == "finished_ok") {
        EXPECT_EQ(served[id], status) << id;
      }
      const json m = api.get("/v1/runs/" + id + "/measurements?limit=100");
      EXPECT_EQ(static_cast<std::int64_t>(m["items"].size()), store::Store(restored / "colorlab.db", store::Store::ReadOnly{})
                                                                  .measurement_count(id))
          << id;
    }
    daemon.terminate();
  }
  // Whatever colorlabd logged after the restore lies in the new epoch.
  store::Database db((restored / "colorlab.db").string(), true);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM event_log WHERE seq > " + report["last_event"].dump() +
                            " AND seq <= " + std::to_string(std::int64_t{1} << fleet::kEpochShift)),
            0);
}

TEST_F(Backup, RestoredBenchShipsAgainInANewEpochWithNoStuckMismatch) {
  SimBench bench(dir_ / "bench", "bench-r", 12);
  const std::string r1 = bench.run_campaign(ExecutionStatus::finished_ok, 12, 4);
  const std::string r2 = bench.run_campaign(ExecutionStatus::aborted, 8, 4);
  const std::string r3 = bench.run_campaign(ExecutionStatus::finished_ok, 10, 5, false);  // under way
  const auto config = bench.write_config(target());
  ASSERT_EQ(ship(config).exit_code, 0);
  auto r = ship(config, "backup");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // After the snapshot the bench finishes r3 and runs r4, ships both, then its disk dies.
  bench.finish(r3, ExecutionStatus::finished_ok);
  const std::string r4 = bench.run_campaign(ExecutionStatus::finished_ok, 6, 3);
  r = ship(config);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::int64_t held = position("bench-r");
  ASSERT_EQ(fleet::epoch_of(held), 0);

  // A new bench from the snapshot. Its store marks r3 interrupted when it opens (as colorlabd does with an
  // execution it cannot resume): the same run ends again, differently, in the new epoch.
  const fs::path restored = dir_ / "restored";
  const auto restored_config = config_for(config, restored);
  r = ship(restored_config, "restore");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json::parse(r.out)["epoch"], 1);
  std::string r5;
  {
    SimBench again(restored, "bench-r", 13);
    ASSERT_EQ(again.store().run(r3)->status, "interrupted");
    // The execution event that ends it, as colorlabd logs one: added here only if opening the store did not.
    store::Database db((restored / "colorlab.db").string(), true);
    auto st = db.prepare("SELECT count(*) FROM event_log WHERE topic = 'execution' AND "
                         "json_extract(payload, '$.run_id') = ?1 AND json_extract(payload, '$.status') = 'interrupted'");
    st.bind(1, std::string_view(r3));
    ASSERT_TRUE(st.step());
    if (st.int64(0) == 0) again.store().append_event("execution", {{"run_id", r3}, {"status", "interrupted"}});
    r5 = again.run_campaign(ExecutionStatus::finished_ok, 7, 3);
  }
  r = ship(restored_config);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const json report = json::parse(r.out);
  EXPECT_EQ(report["runs_shipped"], 1) << r.out;
  EXPECT_TRUE(report["divergences"].empty()) << r.out;
  ASSERT_EQ(report["superseded"].size(), 1u) << r.out;
  EXPECT_EQ(report["superseded"][0]["run_id"], r3);

  auto pg = central();
  const std::int64_t now_held = position("bench-r");
  EXPECT_EQ(fleet::epoch_of(now_held), 1);
  fleet::BenchReader reader(restored / "colorlab.db");
  EXPECT_EQ(pg.query(fleet::kCentralDigestSql, {r5}).text(0, 0), reader.digest(r5));
  // Central keeps what the dead bench shipped: r3 as it finished there, r4 which the snapshot never had.
  EXPECT_EQ(pg.query("SELECT status FROM runs WHERE id = $1", {r3}).text(0, 0), "finished_ok");
  EXPECT_EQ(pg.query("SELECT count(*) FROM runs WHERE id = $1", {r4}).int64(0, 0), 1);
  EXPECT_EQ(pg.query("SELECT count(*) FROM runs WHERE bench_id = 'bench-r'").int64(0, 0), 5);
  EXPECT_EQ(pg.query("SELECT count(*) FROM ship_problems WHERE kind = 'superseded_by_restore' AND run_id = $1", {r3}).int64(0, 0), 1);
  EXPECT_EQ(pg.query("SELECT count(*) FROM ship_problems WHERE kind = 'digest_mismatch'").int64(0, 0), 0);
  // Events: epoch 0 gap-free up to what the dead bench shipped, epoch 1 gap-free from its start, none reused.
  auto ev = pg.query("SELECT seq FROM events WHERE bench_id = 'bench-r' ORDER BY seq");
  std::int64_t expect0 = 1, expect1 = (std::int64_t{1} << fleet::kEpochShift) + 1;
  for (int i = 0; i < ev.rows(); ++i) {
    const std::int64_t s = ev.int64(i, 0);
    if (fleet::epoch_of(s) == 0) {
      ASSERT_EQ(s, expect0++);
    } else {
      ASSERT_EQ(s, expect1++);
    }
  }
  EXPECT_EQ(expect0 - 1, held);
  EXPECT_EQ(expect1 - 1, now_held);

  // Nothing stuck: the next cycle is clean, verify agrees, and the bench's lag is none.
  r = ship(restored_config);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json::parse(r.out)["runs_shipped"], 0);
  r = ship(restored_config, "verify");
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(pg.query("SELECT backlog_runs FROM benches WHERE id = 'bench-r'").int64(0, 0), 0);

  // Restored a second time from the same snapshot: another epoch, never the first restore's.
  r = ship(config_for(config, dir_ / "restored-again"), "restore");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json::parse(r.out)["epoch"], 2);
}

TEST_F(Backup, FullOrFailingDiskFailsClearlyAndLeavesNoHalfSnapshot) {
  SimBench bench(dir_ / "bench", "bench-f", 14);
  bench.run_campaign(ExecutionStatus::finished_ok, 30, 3);
  const auto config = bench.write_config(target());
  const fs::path control = dir_ / "fault-control";
  fs::create_directories(bench.state_dir() / "backup");  // as an earlier backup leaves it
  auto s3 = bucket();
  for (const char* fault : {"ENOSPC", "EIO"}) {
    std::ofstream(control) << fault << " backup\n";
    // The sanitizer presets' options as the preloading integration tests hand them to a preloaded process.
    auto r = ct::run_command({"/usr/bin/env", std::string("LD_PRELOAD=") + COLORLAB_FAULTSHIM,
                              "COLORLAB_FAULT_DIR=" + bench.state_dir().string(), "COLORLAB_FAULT_CONTROL=" + control.string(),
                              "ASAN_OPTIONS=" + ct::asan_options_for_preload(),
                              "TSAN_OPTIONS=" + ct::tsan_options_for_preload(), ct::bin_path("colorlab-ship"), "--config",
                              config.string(), "backup"},
                             std::chrono::seconds(120));
    EXPECT_EQ(r.exit_code, 1) << fault << ": " << r.out << r.err;
    EXPECT_NE(r.err.find("cannot write the snapshot"), std::string::npos) << fault << ": " << r.err;
    EXPECT_NE(r.err.find("nothing of this snapshot was kept"), std::string::npos) << fault << ": " << r.err;
    EXPECT_TRUE(fs::is_empty(bench.state_dir() / "backup")) << fault << ": a half snapshot stayed on the disk";
    EXPECT_THROW(s3.get_part("backups/bench-f/index.json", std::nullopt), Error) << fault << ": the bucket names a snapshot";
  }
  // The disk works again: the same command succeeds, and the bench's own database was never touched.
  std::ofstream(control) << "off\n";
  auto r = ship(config, "backup");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json::parse(s3.get("backups/bench-f/index.json"))["snapshots"].size(), 1u);
  EXPECT_EQ(ct::integrity_check(bench.state_dir()), "ok");
}

TEST_F(Backup, RotationKeepsTheStatedSnapshotsAndDeletesTheRest) {
  SimBench bench(dir_ / "bench", "bench-o", 15);
  bench.run_campaign(ExecutionStatus::finished_ok, 5, 0);
  auto config = bench.write_config(target());
  std::ofstream(config, std::ios::app) << "backup_keep_daily = 2\nbackup_keep_weekly = 1\n";
  // Older snapshots as earlier backups left them (their names are their days): the policy decides by name.
  auto s3 = bucket();
  const fs::path scratch = dir_ / "scratch";
  fs::create_directories(scratch);
  json index{{"format", 1}, {"snapshots", json::array()}, {"restores", json::array()}};
  for (const char* old : {"2026-01-05T030000.000Z", "2026-01-06T030000.000Z", "2026-01-06T040000.000Z"}) {
    std::ofstream(scratch / "x") << old;
    for (const char* obj : {"/colorlab.db", "/manifest.json"}) {
      s3.put_file(std::string("backups/bench-o/") + old + obj, scratch / "x", store::BlobStore::hash_file(scratch / "x"));
    }
    index["snapshots"].push_back({{"name", old}, {"last_event", 1}, {"bytes", 1}});
  }
  std::ofstream(scratch / "index.json") << index.dump();
  s3.put_file("backups/bench-o/index.json", scratch / "index.json", store::BlobStore::hash_file(scratch / "index.json"));

  auto r = ship(config, "backup");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json report = json::parse(r.out);
  // Kept: today's (newest, its day, its week) and 2026-01-06 04:00 (the newest of the second day with one).
  std::set<std::string> gone;
  for (const auto& n : report["rotated_out"]) gone.insert(n.get<std::string>());
  EXPECT_EQ(gone, (std::set<std::string>{"2026-01-05T030000.000Z", "2026-01-06T030000.000Z"}));
  const json now = json::parse(s3.get("backups/bench-o/index.json"));
  ASSERT_EQ(now["snapshots"].size(), 2u);
  EXPECT_FALSE(s3.exists("backups/bench-o/2026-01-05T030000.000Z/colorlab.db"));
  EXPECT_FALSE(s3.exists("backups/bench-o/2026-01-06T030000.000Z/manifest.json"));
  EXPECT_TRUE(s3.exists("backups/bench-o/2026-01-06T040000.000Z/colorlab.db"));
}

}  // namespace
