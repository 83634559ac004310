#include "colorlab/fleet/bench_reader.hpp"

#include <cstdio>
#include <optional>

#include "colorlab/core/error.hpp"
#include "colorlab/fleet/digest.hpp"
#include "colorlab/fleet/pg.hpp"
#include "colorlab/store/ship_log.hpp"

namespace colorlab::fleet {

namespace {

std::optional<std::string> opt_text(store::Statement& st, int col) {
  if (st.is_null(col)) return std::nullopt;
  return st.text(col);
}

std::optional<double> opt_real(store::Statement& st, int col) {
  if (st.is_null(col)) return std::nullopt;
  return st.real(col);
}

// 17 significant digits: PostgreSQL's float8in reads back the same double.
std::string exact(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::optional<std::string> exact(std::optional<double> v) {
  if (!v) return std::nullopt;
  return exact(*v);
}

// From run_blobs alone (not joined to blobs as read() ships them): a reference without its blob row still counts.
void add_blob_refs(store::Database& db, const std::string& run_id, RunDigest& d) {
  auto st = db.prepare("SELECT name, sha256, kind, step FROM run_blobs WHERE run_id = ?1 ORDER BY name");
  st.bind(1, std::string_view(run_id));
  while (st.step()) d.blob_ref(st.text(0), st.text(1), st.text(2), st.text(3));
}

const std::string kEnded = "SELECT seq, json_extract(payload, '$.run_id'), json_extract(payload, '$.status') FROM "
                           "event_log WHERE seq > ?1 AND " +
                           store::kEndEventSql + " ORDER BY seq LIMIT ?2";

}  // namespace

BenchReader::BenchReader(const std::filesystem::path& database) {
  if (!std::filesystem::exists(database)) {
    throw Error(ErrorClass::io_error, "no bench database at " + database.string(),
                "point state_dir in the TOML at colorlabd's state directory");
  }
  db_ = store::Database(database.string(), true);
  db_.exec("PRAGMA query_only = 1");
  db_.exec("PRAGMA busy_timeout = 5000");
}

int BenchReader::schema_version() {
  auto st = db_.prepare("PRAGMA user_version");
  return st.step() ? static_cast<int>(st.int64(0)) : 0;
}

std::int64_t BenchReader::last_event() {
  // sqlite_sequence too: a bench restored a moment ago has its new epoch there before its first event.
  auto st = db_.prepare(
      "SELECT max(coalesce((SELECT max(seq) FROM event_log), 0), "
      "coalesce((SELECT seq FROM sqlite_sequence WHERE name = 'event_log'), 0))");
  return st.step() ? st.int64(0) : 0;
}

std::vector<EndedRun> BenchReader::ended_after(std::int64_t position, int limit) {
  auto st = db_.prepare(kEnded);
  st.bind(1, position).bind(2, static_cast<std::int64_t>(limit));
  std::vector<EndedRun> out;
  while (st.step()) out.push_back({st.int64(0), st.text(1), st.text(2)});
  return out;
}

// The bench's own count (GET /v1/shipping), so central's lag and the bench's cannot disagree.
Backlog BenchReader::backlog(std::int64_t position) { return store::ShipLog(db_).backlog(position); }

RunBatch BenchReader::read(const std::string& bench_id, const EndedRun& run, std::int64_t position) {
  store::ReadTransaction tx(db_);
  RunBatch b;
  b.run = run;
  std::string line;
  // The digest is fed from the rows being encoded (the same snapshot, the same order as digest_locked's
  // queries): the measurements, most of a run, are read once, not twice.
  RunDigest digest;
  {
    auto st = db_.prepare(
        "SELECT seq, id, campaign, params, status, simulated, instruments, created_at, started_at, finished_at, "
        "summary, error, script_sha256 FROM runs WHERE id = ?1");
    st.bind(1, std::string_view(run.run_id));
    if (!st.step()) {
      throw Error(ErrorClass::bad_data, "event " + std::to_string(run.ended_event) + " ended run " + run.run_id +
                                            ", which the bench's database does not hold");
    }
    line.clear();
    copy_field(line, st.text(1));
    copy_field(line, bench_id);
    copy_field(line, std::to_string(st.int64(0)));
    for (int c : {2, 3, 4}) copy_field(line, st.text(c));
    copy_field(line, std::to_string(st.int64(5)));
    copy_field(line, st.text(6));
    copy_field(line, st.text(7));
    for (int c : {8, 9, 10, 11, 12}) copy_field(line, opt_text(st, c));
    copy_field(line, std::to_string(run.ended_event), true);
    b.runs = line;
    digest.run(st.text(1), st.text(4), opt_text(st, 9), opt_text(st, 10), opt_text(st, 11), st.text(3));
  }
  {
    auto st = db_.prepare(
        "SELECT id, run_id, campaign, status, progress, step, created_at, updated_at, error, reason, steps_committed "
        "FROM executions WHERE run_id = ?1 ORDER BY id");
    st.bind(1, std::string_view(run.run_id));
    while (st.step()) {
      line.clear();
      for (int c : {0, 1, 2, 3}) copy_field(line, st.text(c));
      copy_field(line, exact(st.real(4)));
      for (int c : {5, 6, 7}) copy_field(line, st.text(c));
      copy_field(line, opt_text(st, 8));
      copy_field(line, st.text(9));
      copy_field(line, std::to_string(st.int64(10)), true);
      b.executions += line;
    }
  }
  {
    auto st = db_.prepare(
        "SELECT run_id, step, seq, instrument_id, simulated, quantity, value, unit, data, measured_at FROM measurements "
        "WHERE run_id = ?1 ORDER BY seq, step");
    st.bind(1, std::string_view(run.run_id));
    while (st.step()) {
      const std::string step = st.text(1), instrument = st.text(3), quantity = st.text(5), at = st.text(9);
      const auto value = opt_real(st, 6);
      const auto unit = opt_text(st, 7), data = opt_text(st, 8);
      const std::int64_t seq = st.int64(2), simulated = st.int64(4);
      copy_field(b.measurements, st.text(0));
      copy_field(b.measurements, step);
      copy_field(b.measurements, std::to_string(seq));
      copy_field(b.measurements, instrument);
      copy_field(b.measurements, std::to_string(simulated));
      copy_field(b.measurements, quantity);
      copy_field(b.measurements, exact(value));
      copy_field(b.measurements, unit);
      copy_field(b.measurements, data);
      copy_field(b.measurements, at, true);
      digest.measurement(seq, step, instrument, simulated, quantity, unit, data, at, value);
      ++b.measurement_count;
    }
  }
  {
    auto st = db_.prepare(
        "SELECT r.run_id, r.name, r.sha256, r.step, r.kind, r.created_at, b.size, b.media_type, b.meta "
        "FROM run_blobs r JOIN blobs b ON b.sha256 = r.sha256 WHERE r.run_id = ?1 ORDER BY r.name");
    st.bind(1, std::string_view(run.run_id));
    std::vector<std::string> seen;
    while (st.step()) {
      line.clear();
      for (int c = 0; c < 5; ++c) copy_field(line, st.text(c));
      copy_field(line, st.text(5), true);
      b.run_blobs += line;
      const std::string sha = st.text(2);
      bool dup = false;
      for (const auto& s : seen) dup = dup || s == sha;
      if (dup) continue;
      seen.push_back(sha);
      line.clear();
      copy_field(line, sha);
      copy_field(line, std::to_string(st.int64(6)));
      copy_field(line, st.text(7));
      copy_field(line, st.text(8), true);
      b.blobs += line;
      b.blob_files.push_back({sha, static_cast<std::uint64_t>(st.int64(6))});
    }
  }
  {
    auto st = db_.prepare("SELECT seq, time, topic, payload FROM event_log WHERE seq > ?1 AND seq <= ?2 ORDER BY seq");
    st.bind(1, position).bind(2, run.ended_event);
    while (st.step()) {
      line.clear();
      copy_field(line, bench_id);
      copy_field(line, std::to_string(st.int64(0)));
      copy_field(line, st.text(1));
      copy_field(line, st.text(2));
      copy_field(line, st.text(3), true);
      b.events += line;
      ++b.event_count;
    }
  }
  add_blob_refs(db_, run.run_id, digest);
  b.digest = digest.hex();
  return b;
}

std::string BenchReader::digest(const std::string& run_id) {
  store::ReadTransaction tx(db_);
  return digest_locked(run_id);
}

std::string BenchReader::digest_locked(const std::string& run_id) {
  RunDigest d;
  {
    auto st = db_.prepare("SELECT id, status, finished_at, summary, error, params FROM runs WHERE id = ?1");
    st.bind(1, std::string_view(run_id));
    if (!st.step()) throw Error(ErrorClass::not_found, "run " + run_id + " is not in the bench's database");
    d.run(st.text(0), st.text(1), opt_text(st, 2), opt_text(st, 3), opt_text(st, 4), st.text(5));
  }
  {
    auto st = db_.prepare(
        "SELECT seq, step, instrument_id, simulated, quantity, unit, data, measured_at, value FROM measurements "
        "WHERE run_id = ?1 ORDER BY seq, step");
    st.bind(1, std::string_view(run_id));
    while (st.step()) {
      d.measurement(st.int64(0), st.text(1), st.text(2), st.int64(3), st.text(4), opt_text(st, 5), opt_text(st, 6),
                    st.text(7), opt_real(st, 8));
    }
  }
  add_blob_refs(db_, run_id, d);
  return d.hex();
}

}  // namespace colorlab::fleet
