#include "colorlab/fleet/shipper.hpp"

#include <chrono>
#include <exception>
#include <optional>
#include <utility>

#include <nlohmann/json.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/core/log.hpp"
#include "colorlab/fleet/backup.hpp"
#include "colorlab/fleet/bench_reader.hpp"
#include "colorlab/fleet/central_schema.hpp"
#include "colorlab/fleet/digest.hpp"
#include "colorlab/fleet/pg.hpp"
#include "colorlab/fleet/s3.hpp"
#include "colorlab/store/blob_store.hpp"
#include "colorlab/store/schema.hpp"
#include "backup_bucket.hpp"
#include "ship_read_ahead.hpp"

#ifndef COLORLAB_SHIP_VERSION
#define COLORLAB_SHIP_VERSION "unknown"
#endif

namespace colorlab::fleet {

namespace {

// Staging table, its columns in COPY order (bench_reader.cpp writes them so), and the key that makes a re-sent
// row a no-op. Staging tables are per session and emptied at every commit or rollback.
struct Staged {
  const char* table;
  const char* columns;
  const char* key;
};

constexpr Staged kStaged[] = {
    {"runs",
     "id, bench_id, bench_seq, campaign, params, status, simulated, instruments, created_at, started_at, finished_at, "
     "summary, error, script_sha256, ended_event",
     "id"},
    {"executions",
     "id, run_id, campaign, status, progress, step, created_at, updated_at, error, reason, steps_committed", "id"},
    {"measurements", "run_id, step, seq, instrument_id, simulated, quantity, value, unit, data, measured_at",
     "run_id, step"},
    {"blobs", "sha256, size, media_type, meta", "sha256"},
    {"run_blobs", "run_id, name, sha256, step, kind, created_at", "run_id, name"},
    {"events", "bench_id, seq, time, topic, payload", "bench_id, seq"},
};

const std::string& batch_part(const RunBatch& b, int i) {
  switch (i) {
    case 0: return b.runs;
    case 1: return b.executions;
    case 2: return b.measurements;
    case 3: return b.blobs;
    case 4: return b.run_blobs;
    default: return b.events;
  }
}

void check_bench_schema(BenchReader& bench) {
  const int v = bench.schema_version();
  if (v > store::kSchemaVersion) {
    throw Error(ErrorClass::conflict,
                "the bench's database has schema version " + std::to_string(v) + ", newer than this colorlab-ship (" +
                    std::to_string(store::kSchemaVersion) + ")",
                "upgrade colorlab-ship to the same version as colorlabd on this bench");
  }
}

// Registers the bench (or refreshes its name, version and last_seen) and returns the position central holds.
std::int64_t register_bench(Pg& pg, const ShipConfig& c, int bench_schema) {
  auto r = pg.query(
      "INSERT INTO benches (id, name, software_version, bench_schema) VALUES ($1, $2, $3, $4) "
      "ON CONFLICT (id) DO UPDATE SET name = excluded.name, software_version = excluded.software_version, "
      "bench_schema = excluded.bench_schema, last_seen = now() RETURNING shipped_position",
      {c.bench_id, c.bench_name, std::string(COLORLAB_SHIP_VERSION), std::to_string(bench_schema)});
  return r.int64(0, 0);
}

void create_staging(Pg& pg) {
  for (const auto& s : kStaged) {
    pg.exec(std::string("CREATE TEMP TABLE IF NOT EXISTS stage_") + s.table + " (LIKE " + s.table +
            " INCLUDING DEFAULTS) ON COMMIT DELETE ROWS");
  }
}

void record_problem(Pg& pg, const std::string& bench_id, const Divergence& d) {
  nlohmann::json detail{{"bench_digest", d.bench_digest}, {"central_digest", d.central_digest}};
  pg.query("INSERT INTO ship_problems (bench_id, run_id, kind, detail) VALUES ($1, $2, 'digest_mismatch', $3)",
           {bench_id, d.run_id, detail.dump()});
  pg.query("UPDATE benches SET last_error = $2 WHERE id = $1",
           {bench_id, "digest mismatch for run " + d.run_id + ": central holds different rows than the bench"});
}

std::string central_digest(Pg& pg, const std::string& run_id) {
  auto r = pg.query(kCentralDigestSql, {run_id});
  return r.rows() == 1 ? r.text(0, 0) : std::string("(run missing)");
}

void rollback(Pg& pg) {
  try {
    pg.exec("ROLLBACK");
  } catch (...) {
  }
}

enum class Outcome {
  committed,
  raced,
  diverged,
  superseded
};

// A bench restored from a snapshot replays what it held then: a run it had not finished may have ended on the
// dead bench after the snapshot and shipped from there, and the restored bench ends it differently (interrupted).
// Central got that run in an earlier epoch of this bench (backup.hpp), so central's copy is the later word.
bool superseded_by_restore(Pg& pg, const RunBatch& b) {
  auto r = pg.query("SELECT ended_event FROM runs WHERE id = $1", {b.run.run_id});
  return r.rows() == 1 && epoch_of(r.int64(0, 0)) < epoch_of(b.run.ended_event);
}

// The replayed run's events still ship (the bench's event history stays whole) and the position passes it; its
// rows do not, and ship_problems says so.
// False when another agent for this bench moved the position meanwhile (as commit_run's `raced`).
bool commit_superseded(Pg& pg, const ShipConfig& c, const RunBatch& b, std::int64_t position, const Divergence& d) {
  pg.exec("BEGIN");
  try {
    auto held = pg.query("SELECT shipped_position FROM benches WHERE id = $1 FOR UPDATE", {c.bench_id});
    if (held.int64(0, 0) != position) {
      rollback(pg);
      return false;
    }
    if (!b.events.empty()) {
      pg.copy_in(std::string("stage_events (") + kStaged[5].columns + ")", b.events);
      pg.exec(std::string("INSERT INTO events (") + kStaged[5].columns + ") SELECT " + kStaged[5].columns +
              " FROM stage_events ON CONFLICT (" + kStaged[5].key + ") DO NOTHING");
    }
    nlohmann::json detail{
        {"bench_digest", d.bench_digest},
        {"central_digest", d.central_digest},
        {"bench_ended_event", b.run.ended_event},
    };
    pg.query("INSERT INTO ship_problems (bench_id, run_id, kind, detail) VALUES ($1, $2, 'superseded_by_restore', $3)",
             {c.bench_id, d.run_id, detail.dump()});
    pg.query("UPDATE benches SET shipped_position = $2, last_seen = now() WHERE id = $1",
             {c.bench_id, std::to_string(b.run.ended_event)});
    pg.exec("COMMIT");
  } catch (...) {
    rollback(pg);
    throw;
  }
  return true;
}

// The run's rows and the bench's new position in one transaction; the digest is compared before COMMIT so a
// divergent run never moves the position.
Outcome commit_run(Pg& pg, const ShipConfig& c, const RunBatch& b, std::int64_t position, Divergence& divergence) {
  pg.exec("BEGIN");
  try {
    auto held = pg.query("SELECT shipped_position FROM benches WHERE id = $1 FOR UPDATE", {c.bench_id});
    if (held.int64(0, 0) != position) {  // another agent for this bench moved it: start over from there
      rollback(pg);
      return Outcome::raced;
    }
    // A run central lacks has none of its runs, executions or measurements rows there either (they reference it
    // and commit with it), so those go straight in by COPY, without the staging tables' second write (shipping
    // reached 35-39 % of raw COPY through them, bench/fleet/ship_speed.py). Blobs are shared between runs and
    // events may be held from an earlier epoch: they keep insert-or-ignore, and run_blobs follows its blobs.
    const bool fresh = pg.query("SELECT 1 FROM runs WHERE id = $1", {b.run.run_id}).rows() == 0;
    auto direct = [fresh](int i) { return fresh && i <= 2; };  // runs, executions, measurements
    for (int i = 0; i < 6; ++i) {
      const auto& part = batch_part(b, i);
      if (part.empty()) continue;
      pg.copy_in(std::string(direct(i) ? "" : "stage_") + kStaged[i].table + " (" + kStaged[i].columns + ")", part);
    }
    for (int i = 0; i < 6; ++i) {
      if (direct(i)) continue;
      const Staged& s = kStaged[i];
      pg.exec(std::string("INSERT INTO ") + s.table + " (" + s.columns + ") SELECT " + s.columns + " FROM stage_" +
              s.table + " ON CONFLICT (" + s.key + ") DO NOTHING");
    }
    const std::string central = central_digest(pg, b.run.run_id);
    if (central != b.digest) {
      divergence = {b.run.run_id, b.digest, central};
      const bool superseded = superseded_by_restore(pg, b);
      rollback(pg);
      if (!superseded) return Outcome::diverged;
      return commit_superseded(pg, c, b, position, divergence) ? Outcome::superseded : Outcome::raced;
    }
    pg.query("UPDATE benches SET shipped_position = $2, last_seen = now(), last_error = NULL WHERE id = $1",
             {c.bench_id, std::to_string(b.run.ended_event)});
    pg.exec("COMMIT");
  } catch (...) {
    rollback(pg);
    throw;
  }
  return Outcome::committed;
}

using Clock = std::chrono::steady_clock;

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// A PostgreSQL text[] literal of run ids (UUIDs: no quote, comma or backslash to escape, but quoted anyway).
std::string text_array(const std::vector<RunBatch>& group) {
  std::string a = "{";
  for (const auto& b : group) {
    if (a.size() > 1) a += ',';
    a += '"';
    for (char ch : b.run.run_id) {
      if (ch == '"' || ch == '\\') a += '\\';
      a += ch;
    }
    a += '"';
  }
  return a + "}";
}

enum class GroupOutcome {
  committed,
  raced,
  mismatch
};

// Consecutive runs' rows and the position after the last of them in one transaction: one fsync'd COMMIT, one
// COPY a table and one digest statement for all of them (a commit a run cost 0.23-0.44 of raw COPY, see
// docs/PERFORMANCE.md). Any run whose digest disagrees rolls the whole group back (`mismatch`); the caller then
// ships the group one run a transaction (commit_run), which commits the runs before it and pinpoints it.
GroupOutcome commit_group(Pg& pg, const ShipConfig& c, const std::vector<RunBatch>& group, std::int64_t position,
                          CycleReport::Seconds& secs) {
  const std::string ids = text_array(group);
  pg.exec("BEGIN");
  try {
    auto held = pg.query("SELECT shipped_position FROM benches WHERE id = $1 FOR UPDATE", {c.bench_id});
    if (held.int64(0, 0) != position) {
      rollback(pg);
      return GroupOutcome::raced;
    }
    // As in commit_run: a run central lacks goes straight in by COPY; one it holds (a re-send after a kill, a
    // divergent duplicate) goes through staging and insert-or-ignore, and the digest judges it.
    std::vector<bool> fresh(group.size(), true);
    {
      auto held_runs = pg.query("SELECT id FROM runs WHERE id = ANY($1::text[])", {ids});
      for (int r = 0; r < held_runs.rows(); ++r) {
        const std::string id = held_runs.text(r, 0);
        for (std::size_t g = 0; g < group.size(); ++g) fresh[g] = fresh[g] && group[g].run.run_id != id;
      }
    }
    auto t = Clock::now();
    std::vector<bool> staged(6, false);
    for (int i = 0; i < 6; ++i) {
      std::vector<const std::string*> direct, stage;
      for (std::size_t g = 0; g < group.size(); ++g) {
        const auto& part = batch_part(group[g], i);
        if (part.empty()) continue;
        (fresh[g] && i <= 2 ? direct : stage).push_back(&part);
      }
      const std::string cols = std::string(" (") + kStaged[i].columns + ")";
      if (!direct.empty()) pg.copy_in(kStaged[i].table + cols, direct);
      if (!stage.empty()) pg.copy_in(std::string("stage_") + kStaged[i].table + cols, stage);
      staged[i] = !stage.empty();
    }
    secs.copy += since(t);
    t = Clock::now();
    for (int i = 0; i < 6; ++i) {
      if (!staged[i]) continue;
      const Staged& s = kStaged[i];
      pg.exec(std::string("INSERT INTO ") + s.table + " (" + s.columns + ") SELECT " + s.columns + " FROM stage_" +
              s.table + " ON CONFLICT (" + s.key + ") DO NOTHING");
    }
    secs.merge += since(t);
    t = Clock::now();
    auto digests = pg.query(kCentralDigestsSql, {ids});
    int agreed = 0;
    for (int r = 0; r < digests.rows(); ++r) {
      const std::string id = digests.text(r, 0), central = digests.text(r, 1);
      for (const auto& b : group) agreed += b.run.run_id == id && b.digest == central ? 1 : 0;
    }
    secs.digest += since(t);
    if (agreed != static_cast<int>(group.size())) {
      rollback(pg);
      return GroupOutcome::mismatch;
    }
    pg.query("UPDATE benches SET shipped_position = $2, last_seen = now(), last_error = NULL WHERE id = $1",
             {c.bench_id, std::to_string(group.back().run.ended_event)});
    t = Clock::now();
    pg.exec("COMMIT");
    secs.commit += since(t);
  } catch (...) {
    rollback(pg);
    throw;
  }
  return GroupOutcome::committed;
}

// The bench's backlog after `position`, for central's GET /v1/benches. Outside the run transactions: it is a
// report of the moment, and a cycle that fails before this leaves the previous report (with its backlog_at).
void record_backlog(Pg& pg, BenchReader& bench, const std::string& bench_id, std::int64_t position) {
  const Backlog b = bench.backlog(position);
  pg.query("UPDATE benches SET backlog_runs = $2, oldest_unshipped_run = $3, oldest_unshipped_ended = $4::timestamptz, "
           "backlog_at = now() WHERE id = $1",
           {bench_id, std::to_string(b.runs), b.oldest_run_id.empty() ? std::nullopt : std::optional(b.oldest_run_id),
            b.oldest_ended_at.empty() ? std::nullopt : std::optional(b.oldest_ended_at)});
}

// Every blob the run references, into the bucket unless it is there already; returns how many went.
int upload_blobs(S3Client& s3, store::BlobStore& files, const ShipConfig& c, const RunBatch& b) {
  int uploaded = 0;
  for (const auto& blob : b.blob_files) {
    const std::string key = blob_key(blob.sha256);
    if (s3.exists(key)) continue;
    const auto path = files.path_of(blob.sha256);
    if (!std::filesystem::exists(path)) {
      throw Error(ErrorClass::io_error,
                  "run " + b.run.run_id + " references blob " + blob.sha256 +
                      ", whose file is missing from " + c.blob_root().string(),
                  "colorlab blobs check; shipping cannot pass this run until the file is restored");
    }
    s3.put_file(key, path, blob.sha256);
    ++uploaded;
  }
  return uploaded;
}

}  // namespace

void central_init(const ShipConfig& config) {
  Pg pg(config.postgres);
  central_migrate(pg);
}

CycleReport ship_cycle(const ShipConfig& c) {
  BenchReader bench(c.database_path());
  check_bench_schema(bench);
  Pg pg(c.postgres);
  central_require(pg);
  S3Client s3 = bucket_for(c);
  store::BlobStore files(c.blob_root());
  const int bench_schema = bench.schema_version();

  CycleReport report;
  std::int64_t position = register_bench(pg, c, bench_schema);
  report.position_before = position;
  // Central may be ahead of the local note (a kill after COMMIT); retention reads the note, so catch it up.
  write_shipped_position(c.shipped_position_file(), position);
  create_staging(pg);

  int budget = c.batch_runs;
  enum class Next {
    go_on,
    restart,
    stop
  };
  // One transaction's runs into central (commit_group), or on a digest mismatch one run a transaction as shipping
  // always did, to commit the runs before the divergent one, report it and stop before it.
  auto settle = [&](const std::vector<RunBatch>& group) {
    const GroupOutcome g = commit_group(pg, c, group, position, report.seconds);
    if (g == GroupOutcome::raced) {
      position = register_bench(pg, c, bench_schema);
      return Next::restart;
    }
    if (g == GroupOutcome::committed) {
      position = group.back().run.ended_event;
      write_shipped_position(c.shipped_position_file(), position);
      ++report.transactions;
      for (const auto& b : group) {
        ++report.runs_shipped;
        report.measurements += b.measurement_count;
        report.events += b.event_count;
      }
      budget -= static_cast<int>(group.size());
      return Next::go_on;
    }
    for (const auto& b : group) {
      Divergence d;
      switch (commit_run(pg, c, b, position, d)) {
        case Outcome::raced:
          position = register_bench(pg, c, bench_schema);
          return Next::restart;
        case Outcome::diverged:
          record_problem(pg, c.bench_id, d);
          log::error("ship", "run " + d.run_id + " differs between the bench (digest " + d.bench_digest +
                                 ") and central (" + d.central_digest + "); shipping stops before it");
          report.divergences.push_back(d);
          return Next::stop;
        case Outcome::superseded:
          log::warning("ship", "run " + d.run_id + " ended again on this restored bench; central keeps the copy it "
                                                   "shipped before the restore (ship_problems: superseded_by_restore)");
          report.superseded.push_back(d);
          position = b.run.ended_event;
          write_shipped_position(c.shipped_position_file(), position);
          report.events += b.event_count;
          --budget;
          break;
        case Outcome::committed:
          position = b.run.ended_event;
          write_shipped_position(c.shipped_position_file(), position);
          ++report.transactions;
          ++report.runs_shipped;
          report.measurements += b.measurement_count;
          report.events += b.event_count;
          --budget;
          break;
      }
    }
    return Next::go_on;
  };
  // A failure while a transaction's runs are gathered (reading the bench, uploading blobs): the runs gathered
  // before it still commit, as when each run was its own transaction, then the failure ends the cycle. Returns
  // only when settling them stopped shipping itself (a divergence, already reported), which ends the cycle instead.
  auto settle_before_failure = [&](const std::vector<RunBatch>& group, std::exception_ptr failure) {
    if (group.empty() || settle(group) != Next::stop) std::rethrow_exception(failure);
  };

  Next next = Next::go_on;
  while (budget > 0 && next != Next::stop) {
    auto ended = bench.ended_after(position, budget);
    if (ended.empty()) break;
    ReadAhead ahead(c.database_path(), c.bench_id, std::move(ended), position, c.transaction_measurements);
    std::optional<RunBatch> held;  // read, but for the next transaction
    next = Next::go_on;
    while (next == Next::go_on) {
      // The next transaction's runs, each read from the position after the one before it (its events follow
      // on), blobs uploaded before any row that names them. A run id seen twice (ended again) waits for the next
      // transaction: a run's rows go in once per transaction.
      std::vector<RunBatch> group;
      std::int64_t measurements = 0;
      while (static_cast<int>(group.size()) < c.transaction_runs && measurements < c.transaction_measurements) {
        std::optional<RunBatch> b;
        if (held) {
          b = std::exchange(held, std::nullopt);  // taken, and no longer held
        } else {
          try {
            b = ahead.next();
          } catch (...) {
            // A run the bench cannot read (e.g. an end event whose run is gone): the position stops right at it.
            settle_before_failure(group, std::current_exception());
            next = Next::stop;
            break;
          }
        }
        if (!b) break;
        bool again = false;
        for (const auto& g : group) again = again || g.run.run_id == b->run.run_id;
        if (again) {
          held = std::move(b);
          break;
        }
        const auto t = Clock::now();
        try {
          report.blobs_uploaded += upload_blobs(s3, files, c, *b);
        } catch (...) {
          // The store failing mid-transaction: a store that fails now and then does not hold back what was ready.
          settle_before_failure(group, std::current_exception());
          next = Next::stop;
          break;
        }
        report.seconds.blobs += since(t);
        measurements += b->measurement_count;
        group.push_back(std::move(*b));
      }
      if (next == Next::stop || group.empty()) break;
      next = settle(group);
    }
    report.seconds.read += ahead.read_seconds();
    report.seconds.read_wait += ahead.wait_seconds();
  }
  report.position_after = position;
  record_backlog(pg, bench, c.bench_id, position);
  return report;
}

std::vector<Divergence> verify_shipped(const ShipConfig& c) {
  BenchReader bench(c.database_path());
  check_bench_schema(bench);
  Pg pg(c.postgres);
  central_require(pg);
  std::vector<Divergence> out;
  // After a restore (backup.hpp) central holds runs the restored bench never had (they ended after its
  // snapshot) and runs it ended again differently (superseded_by_restore): central's copies are the record then.
  const std::int64_t epoch = epoch_of(bench.last_event());
  auto runs = pg.query(
      "SELECT id, ended_event, EXISTS (SELECT 1 FROM ship_problems p WHERE p.bench_id = runs.bench_id AND "
      "p.run_id = runs.id AND p.kind = 'superseded_by_restore') FROM runs WHERE bench_id = $1 ORDER BY ended_event",
      {c.bench_id});
  for (int i = 0; i < runs.rows(); ++i) {
    const std::string id = runs.text(i, 0);
    if (runs.text(i, 2) == "t") continue;
    std::string mine;
    try {
      mine = bench.digest(id);
    } catch (const Error& e) {
      if (e.cls() != ErrorClass::not_found) throw;
      if (epoch_of(runs.int64(i, 1)) < epoch) continue;
      mine = "(run missing on the bench)";
    }
    const std::string theirs = central_digest(pg, id);
    if (mine != theirs) {
      Divergence d{id, mine, theirs};
      record_problem(pg, c.bench_id, d);
      log::error("ship", "run " + id + " differs between the bench (digest " + mine + ") and central (" + theirs + ")");
      out.push_back(d);
    }
  }
  return out;
}

}  // namespace colorlab::fleet
