#include "colorlab/store/store.hpp"

#include <cmath>

#include <sqlite3.h>

#include "colorlab/core/error.hpp"
#include "colorlab/core/ids.hpp"
#include "colorlab/core/log.hpp"
#include "colorlab/store/blob_index.hpp"
#include "colorlab/store/busy_retry.hpp"
#include "colorlab/store/schema.hpp"
#include "colorlab/store/ship_log.hpp"
#include "colorlab/store/wal_policy.hpp"

namespace colorlab::store {

namespace fs = std::filesystem;
using protocol::ExecutionStatus;

namespace {

nlohmann::json parse_json_column(const std::string& text) {
  if (text.empty()) return nullptr;
  return nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
}

std::string dump_or_empty(const nlohmann::json& j) { return j.is_null() ? std::string() : j.dump(); }

constexpr const char* kExecutionColumns =
    "id, run_id, campaign, status, progress, step, created_at, updated_at, error, reason, resume_attempts, "
    "steps_committed, script_sha256, random_seed, suspension";

}  // namespace

nlohmann::json ExecutionRecord::to_json() const {
  nlohmann::json j{
      {"id", id},
      {"run_id", run_id},
      {"campaign", campaign},
      {"status", protocol::to_string(status)},
      {"progress", progress},
      {"step", step},
      {"created_at", created_at},
      {"updated_at", updated_at},
  };
  if (!error.is_null()) j["error"] = error;
  j["reason"] = reason;
  if (!suspension.is_null()) j["suspension"] = suspension;
  j["resume_attempts"] = resume_attempts;
  j["steps_committed"] = steps_committed;
  if (!script_sha256.empty()) j["script_sha256"] = script_sha256;
  return j;
}

nlohmann::json MeasurementRecord::to_json() const {
  nlohmann::json j{{"seq", seq},
                   {"step", step},
                   {"instrument_id", instrument_id},
                   {"simulated", simulated},
                   {"quantity", quantity},
                   {"unit", unit},
                   {"measured_at", measured_at}};
  j["value"] = value ? nlohmann::json(*value) : nlohmann::json(nullptr);
  if (!data.is_null()) j["data"] = data;
  return j;
}

nlohmann::json RunRecord::to_json() const {
  nlohmann::json j{{"id", id},
                   {"campaign", campaign},
                   {"params", params},
                   {"status", status},
                   {"simulated", simulated},
                   {"instruments", instruments},
                   {"created_at", created_at}};
  j["started_at"] = started_at ? nlohmann::json(*started_at) : nlohmann::json(nullptr);
  j["finished_at"] = finished_at ? nlohmann::json(*finished_at) : nlohmann::json(nullptr);
  j["summary"] = summary;
  if (!error.is_null()) j["error"] = error;
  if (!script_sha256.empty()) j["script"] = {{"sha256", script_sha256}, {"name", campaign + ".lua"}};
  return j;
}

Store::Store(const fs::path& database_path) {
  std::error_code ec;
  fs::create_directories(database_path.parent_path().empty() ? fs::path(".") : database_path.parent_path(), ec);
  if (ec) {
    throw Error(ErrorClass::io_error, "cannot create state directory " + database_path.parent_path().string() + ": " +
                                          ec.message());
  }
  db_ = Database(database_path.string(), false);
  retry_promptly_when_busy(db_, kBusyTimeout);
  {
    auto st = db_.prepare("PRAGMA journal_mode = WAL");
    st.step();
  }
  db_.exec("PRAGMA synchronous = FULL");
  db_.exec("PRAGMA foreign_keys = ON");
  apply_wal_policy(db_);
  db_.exec("PRAGMA temp_store = MEMORY");
  {
    auto st = db_.prepare("PRAGMA quick_check");
    if (st.step() && st.text(0) != "ok") {
      throw Error(ErrorClass::io_error, "database " + database_path.string() + " failed quick_check: " + st.text(0),
                  "restore from backup, or try: sqlite3 colorlab.db .recover");
    }
  }
  migrate(db_);

  // Executions from before scripts were stored cannot be replayed: finalise them so no tool waits
  // for them forever. Every other unfinished execution is the daemon's to resume.
  Transaction tx(db_);
  std::string now = now_iso8601();
  db_.prepare(
         "UPDATE runs SET status = 'interrupted', finished_at = ?1 WHERE status IN ('waiting', 'running') AND "
         "script_sha256 IS NULL")
      .bind(1, std::string_view(now))
      .run();
  interrupted_at_open_ = db_.changes();
  db_.prepare(
         "UPDATE executions SET status = 'interrupted', updated_at = ?1, reason = 'the process running it ended and "
         "it has no stored script to resume from' WHERE status IN ('waiting', 'running', 'paused', 'suspended') AND "
         "script_sha256 IS NULL")
      .bind(1, std::string_view(now))
      .run();
  // Those just finalised, and any an older colorlabd finalised so: without an end event they would never ship.
  const int recorded = record_missing_end_events(db_, now);
  tx.commit();
  if (interrupted_at_open_ > 0) {
    log::warning("store", std::to_string(interrupted_at_open_) + " run(s) from a previous process marked interrupted");
  }
  if (recorded > 0) {
    log::info("store", std::to_string(recorded) + " ended run(s) without an end event given one, so that they ship");
  }
}

Store::Store(const fs::path& database_path, ReadOnly) {
  db_ = Database(database_path.string(), true);
  retry_promptly_when_busy(db_, kBusyTimeout);
  db_.exec("PRAGMA query_only = ON");
  db_.exec("PRAGMA temp_store = MEMORY");
}

Store::Store(const fs::path& database_path, SecondWriter) {
  db_ = Database(database_path.string(), false);
  retry_promptly_when_busy(db_, kBusyTimeout);
  db_.exec("PRAGMA synchronous = FULL");
  db_.exec("PRAGMA foreign_keys = ON");
  apply_wal_policy(db_);
  db_.exec("PRAGMA temp_store = MEMORY");
}

void Store::hand_wal_checkpoints_to(std::function<void()> ask) { hand_checkpoints_elsewhere(db_, std::move(ask)); }

void Store::checkpoint_wal() noexcept { checkpoint_passive(db_); }

std::uint64_t Store::wal_checkpoints_run() const {
  const auto* state = db_.wal_hook_state();
  return state ? state->checkpoints : 0;
}

Store::Created Store::create_execution(const NewRun& run) {
  if (run.idempotency_key) {
    if (auto existing = execution_with_idempotency_key(*run.idempotency_key)) return {*existing, false};
  }
  ExecutionRecord e;
  e.id = new_uuid_v7();
  e.run_id = new_uuid_v7();
  e.campaign = run.campaign;
  e.created_at = e.updated_at = now_iso8601();

  e.script_sha256 = run.script_sha256;
  e.random_seed = run.random_seed;

  Transaction tx(db_);
  std::optional<std::string> sha;
  if (!run.script_sha256.empty()) {
    sha = run.script_sha256;
    db_.prepare("INSERT OR IGNORE INTO scripts (sha256, name, source, first_seen) VALUES (?1, ?2, ?3, ?4)")
        .bind(1, std::string_view(run.script_sha256))
        .bind(2, std::string_view(run.campaign))
        .bind(3, std::string_view(run.script_source))
        .bind(4, std::string_view(e.created_at))
        .run();
  }
  db_.prepare(
         "INSERT INTO runs (id, campaign, params, status, simulated, instruments, created_at, script_sha256) "
         "VALUES (?1, ?2, ?3, 'waiting', ?4, ?5, ?6, ?7)")
      .bind(1, std::string_view(e.run_id))
      .bind(2, std::string_view(run.campaign))
      .bind(3, std::string_view(run.params.dump()))
      .bind(4, static_cast<std::int64_t>(run.simulated))
      .bind(5, std::string_view(run.instruments.dump()))
      .bind(6, std::string_view(e.created_at))
      .bind(7, sha)
      .run();
  db_.prepare(
         "INSERT INTO executions (id, run_id, campaign, status, idempotency_key, created_at, updated_at, script_sha256, "
         "random_seed) VALUES (?1, ?2, ?3, 'waiting', ?4, ?5, ?5, ?6, ?7)")
      .bind(1, std::string_view(e.id))
      .bind(2, std::string_view(e.run_id))
      .bind(3, std::string_view(run.campaign))
      .bind(4, run.idempotency_key)
      .bind(5, std::string_view(e.created_at))
      .bind(6, sha)
      .bind(7, static_cast<std::int64_t>(run.random_seed & 0x7fffffffffffffffULL))
      .run();
  append_event("execution", e.to_json());
  tx.commit();
  return {e, true};
}

void Store::update_execution(const std::string& id, ExecutionStatus status, double progress, const std::string& step,
                             const nlohmann::json& error) {
  std::string now = now_iso8601();
  db_.prepare("UPDATE executions SET status = ?2, progress = ?3, step = ?4, updated_at = ?5, error = ?6 WHERE id = ?1")
      .bind(1, std::string_view(id))
      .bind(2, protocol::to_string(status))
      .bind(3, progress)
      .bind(4, std::string_view(step))
      .bind(5, std::string_view(now))
      .bind(6, error.is_null() ? std::optional<std::string>() : std::optional<std::string>(error.dump()))
      .run();
}

void Store::mark_run_started(const std::string& run_id) {
  db_.prepare("UPDATE runs SET status = 'running', started_at = ?2 WHERE id = ?1")
      .bind(1, std::string_view(run_id))
      .bind(2, std::string_view(now_iso8601()))
      .run();
}

void Store::start_execution(const ExecutionRecord& execution) {
  Transaction tx(db_);
  mark_run_started(execution.run_id);
  update_execution(execution.id, ExecutionStatus::running, 0, "starting");
  tx.commit();
}

void Store::report_progress(const std::string& execution_id, double progress, const std::string& step) {
  Transaction tx(db_);
  update_execution(execution_id, ExecutionStatus::running, progress, step);
  append_event("progress", {{"execution_id", execution_id}, {"progress", progress}, {"step", step}});
  tx.commit();
}

void Store::finish_execution(const ExecutionRecord& execution, ExecutionStatus status, const std::string& step,
                             const nlohmann::json& summary, const nlohmann::json& error, const std::string& reason) {
  Transaction tx(db_);
  finish_run(execution.run_id, status, summary, error);
  double progress = execution.progress;
  if (auto current = this->execution(execution.id)) progress = current->progress;
  update_execution(execution.id, status, status == ExecutionStatus::finished_ok ? 1.0 : progress, step, error);
  db_.prepare("UPDATE executions SET reason = ?2, suspension = NULL WHERE id = ?1")
      .bind(1, std::string_view(execution.id))
      .bind(2, std::string_view(reason))
      .run();
  nlohmann::json event{{"execution_id", execution.id},
                       {"run_id", execution.run_id},
                       {"status", protocol::to_string(status)},
                       {"reason", reason}};
  // The console shows why a run ended as it happens, not only after reading it again.
  if (!error.is_null()) event["error"] = error;
  append_event("execution", event);
  tx.commit();
}

void Store::set_execution_status(const ExecutionRecord& execution, ExecutionStatus status, const std::string& reason,
                                 const nlohmann::json& event_extra, const nlohmann::json& suspension) {
  Transaction tx(db_);
  std::string now = now_iso8601();
  const bool suspended = status == ExecutionStatus::suspended && !suspension.is_null();
  db_.prepare("UPDATE executions SET status = ?2, reason = ?3, updated_at = ?4, suspension = ?5 WHERE id = ?1")
      .bind(1, std::string_view(execution.id))
      .bind(2, protocol::to_string(status))
      .bind(3, std::string_view(reason))
      .bind(4, std::string_view(now))
      .bind(5, suspended ? std::optional<std::string>(suspension.dump()) : std::optional<std::string>())
      .run();
  db_.prepare("UPDATE runs SET status = ?2, started_at = COALESCE(started_at, ?3) WHERE id = ?1")
      .bind(1, std::string_view(execution.run_id))
      .bind(2, protocol::to_string(status))
      .bind(3, std::string_view(now))
      .run();
  nlohmann::json event{{"execution_id", execution.id},
                       {"run_id", execution.run_id},
                       {"status", protocol::to_string(status)},
                       {"reason", reason}};
  if (suspended) event["suspension"] = suspension;
  if (event_extra.is_object()) event.update(event_extra);
  append_event("execution", event);
  tx.commit();
}

int Store::begin_resume(const std::string& execution_id) {
  Transaction tx(db_);
  db_.prepare("UPDATE executions SET resume_attempts = resume_attempts + 1 WHERE id = ?1")
      .bind(1, std::string_view(execution_id))
      .run();
  auto st = db_.prepare("SELECT resume_attempts FROM executions WHERE id = ?1");
  st.bind(1, std::string_view(execution_id));
  int attempts = st.step() ? static_cast<int>(st.int64(0)) : 0;
  tx.commit();
  return attempts;
}

void Store::commit_step(const ExecutionRecord& execution, const StepRecord& step) {
  Transaction tx(db_);
  std::string now = now_iso8601();
  if (!step.journal.empty()) {
    auto ins = db_.prepare("INSERT INTO journal (execution_id, seq, call, args, result, at) VALUES (?1, ?2, ?3, ?4, ?5, ?6)");
    for (const auto& j : step.journal) {
      ins.bind(1, std::string_view(execution.id))
          .bind(2, j.seq)
          .bind(3, std::string_view(j.call))
          .bind(4, std::string_view(j.args.dump()))
          .bind(5, std::string_view(j.result.dump()))
          .bind(6, std::string_view(now));
      ins.run();
      ins.reset();
    }
  }
  if (!step.measurements.empty()) {
    std::int64_t seq = 0;
    {
      auto st = db_.prepare("SELECT COALESCE(MAX(seq), 0) FROM measurements WHERE run_id = ?1");
      st.bind(1, std::string_view(execution.run_id));
      if (st.step()) seq = st.int64(0);
    }
    auto ins = db_.prepare(
        "INSERT INTO measurements (run_id, seq, step, instrument_id, simulated, quantity, value, unit, data, measured_at) "
        "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10)");
    for (const auto& m : step.measurements) {
      ins.bind(1, std::string_view(execution.run_id))
          .bind(2, ++seq)
          .bind(3, std::string_view(m.step))
          .bind(4, std::string_view(m.instrument_id))
          .bind(5, static_cast<std::int64_t>(m.simulated))
          .bind(6, std::string_view(m.quantity));
      if (m.value && std::isfinite(*m.value)) {
        ins.bind(7, *m.value);
      } else {
        ins.bind_null(7);
      }
      ins.bind(8, std::string_view(m.unit)).bind(9, std::string_view(dump_or_empty(m.data))).bind(10, std::string_view(now));
      ins.run();
      ins.reset();
    }
  }
  if (!step.timings.empty()) {
    auto up = db_.prepare(
        "INSERT INTO call_timings (key, time_scale, n, sum_s, sum_sq, updated_at) VALUES (?1, ?2, 1, ?3, ?3 * ?3, ?4) "
        "ON CONFLICT (key, time_scale) DO UPDATE SET n = n + 1, sum_s = sum_s + excluded.sum_s, "
        "sum_sq = sum_sq + excluded.sum_sq, updated_at = excluded.updated_at");
    for (const auto& t : step.timings) {
      if (!std::isfinite(t.lab_seconds) || t.lab_seconds < 0) continue;
      up.bind(1, std::string_view(t.key)).bind(2, step.time_scale).bind(3, t.lab_seconds).bind(4, std::string_view(now));
      up.run();
      up.reset();
    }
  }
  insert_step_blobs(db_, execution.run_id, step.step, step.blobs, now);
  if (step.instruments) {
    db_.prepare("UPDATE runs SET instruments = ?2 WHERE id = ?1")
        .bind(1, std::string_view(execution.run_id))
        .bind(2, std::string_view(step.instruments->dump()))
        .run();
  }
  // Only a step that did something (a lab call or a measurement) proves a resume got past the
  // point that killed the previous process.
  bool progressed = !step.journal.empty() || !step.measurements.empty();
  db_.prepare(
         "UPDATE executions SET progress = ?2, step = ?3, updated_at = ?4, steps_committed = steps_committed + 1, "
         "resume_attempts = CASE WHEN ?5 THEN 0 ELSE resume_attempts END WHERE id = ?1")
      .bind(1, std::string_view(execution.id))
      .bind(2, step.progress)
      .bind(3, std::string_view(step.step))
      .bind(4, std::string_view(now))
      .bind(5, static_cast<std::int64_t>(progressed))
      .run();
  append_event("progress", {{"execution_id", execution.id},
                            {"run_id", execution.run_id},
                            {"progress", step.progress},
                            {"step", step.step},
                            {"measurements", step.measurements.size()}});
  tx.commit();
  bound_wal(db_);
}

std::vector<JournalRow> Store::journal(const std::string& execution_id) {
  auto st = db_.prepare("SELECT seq, call, args, result FROM journal WHERE execution_id = ?1 ORDER BY seq");
  st.bind(1, std::string_view(execution_id));
  std::vector<JournalRow> out;
  while (st.step()) {
    out.push_back(JournalRow{st.int64(0), st.text(1), parse_json_column(st.text(2)), parse_json_column(st.text(3))});
  }
  return out;
}

std::map<std::string, LearnedTiming> Store::call_timings(double time_scale) {
  // Per key the figure learned nearest to how the lab runs now, by ratio (×50 is nearer ×100 than ×1).
  const double here = std::log(time_scale > 0 ? time_scale : 1.0);
  auto st = db_.prepare("SELECT key, time_scale, n, sum_s, sum_sq FROM call_timings WHERE n > 0 AND time_scale > 0");
  std::map<std::string, LearnedTiming> out;
  while (st.step()) {
    LearnedTiming t;
    t.time_scale = st.real(1);
    t.n = st.int64(2);
    const double sum = st.real(3), sum_sq = st.real(4);
    t.mean_s = sum / static_cast<double>(t.n);
    const double var = t.n > 1 ? (sum_sq - sum * sum / static_cast<double>(t.n)) / static_cast<double>(t.n - 1) : 0.0;
    t.stdev_s = var > 0 ? std::sqrt(var) : 0.0;
    auto [it, fresh] = out.emplace(st.text(0), t);
    if (!fresh && std::abs(std::log(t.time_scale) - here) < std::abs(std::log(it->second.time_scale) - here)) it->second = t;
  }
  return out;
}

std::set<std::string> Store::measurement_steps(const std::string& run_id) {
  auto st = db_.prepare("SELECT step FROM measurements WHERE run_id = ?1");
  st.bind(1, std::string_view(run_id));
  std::set<std::string> out;
  while (st.step()) out.insert(st.text(0));
  return out;
}

std::optional<std::string> Store::script_source(const std::string& sha256) {
  auto st = db_.prepare("SELECT source FROM scripts WHERE sha256 = ?1");
  st.bind(1, std::string_view(sha256));
  if (!st.step()) return std::nullopt;
  return st.text(0);
}

ExecutionRecord Store::read_execution(Statement& st) {
  ExecutionRecord e;
  e.id = st.text(0);
  e.run_id = st.text(1);
  e.campaign = st.text(2);
  e.status = protocol::execution_status_from_string(st.text(3)).value_or(ExecutionStatus::finished_error);
  e.progress = st.real(4);
  e.step = st.text(5);
  e.created_at = st.text(6);
  e.updated_at = st.text(7);
  e.error = parse_json_column(st.text(8));
  e.reason = st.text(9);
  e.resume_attempts = static_cast<int>(st.int64(10));
  e.steps_committed = st.int64(11);
  if (!st.is_null(12)) e.script_sha256 = st.text(12);
  e.random_seed = static_cast<std::uint64_t>(st.int64(13));
  if (!st.is_null(14)) e.suspension = parse_json_column(st.text(14));
  return e;
}

std::vector<ExecutionRecord> Store::unfinished_executions() {
  auto st = db_.prepare(std::string("SELECT ") + kExecutionColumns +
                        " FROM executions WHERE status IN ('waiting', 'running', 'paused', 'suspended') ORDER BY created_at, id");
  std::vector<ExecutionRecord> out;
  while (st.step()) out.push_back(read_execution(st));
  return out;
}

nlohmann::json Store::measurement_summary(const std::string& run_id) {
  auto st = db_.prepare(
      "SELECT quantity, unit, COUNT(*), COUNT(value), AVG(value), MIN(value), MAX(value), "
      "SUM(value * value), SUM(value) FROM measurements WHERE run_id = ?1 GROUP BY quantity, unit ORDER BY quantity, unit");
  st.bind(1, std::string_view(run_id));
  nlohmann::json out = nlohmann::json::object();
  while (st.step()) {
    nlohmann::json q{{"unit", st.text(1)}, {"count", st.int64(2)}};
    std::int64_t n = st.int64(3);
    if (n > 0) {
      double mean = st.real(4), sum_sq = st.real(7), sum = st.real(8);
      q["mean"] = mean;
      q["min"] = st.real(5);
      q["max"] = st.real(6);
      q["stdev"] = n > 1 ? std::sqrt(std::max(0.0, (sum_sq - sum * mean) / static_cast<double>(n - 1))) : 0.0;
    }
    std::string key = st.text(0);
    if (out.contains(key)) key += " [" + st.text(1) + "]";
    out[key] = q;
  }
  return out;
}

void Store::finish_run(const std::string& run_id, ExecutionStatus status, const nlohmann::json& summary,
                       const nlohmann::json& error) {
  std::optional<std::string> listed;
  if (!summary.is_null()) {
    nlohmann::json slim = summary;
    if (slim.is_object()) slim.erase("script");
    listed = slim.dump();
  }
  db_.prepare("UPDATE runs SET status = ?2, finished_at = ?3, summary = ?4, error = ?5, list_summary = ?6 WHERE id = ?1")
      .bind(1, std::string_view(run_id))
      .bind(2, protocol::to_string(status))
      .bind(3, std::string_view(now_iso8601()))
      .bind(4, summary.is_null() ? std::optional<std::string>() : std::optional<std::string>(summary.dump()))
      .bind(5, error.is_null() ? std::optional<std::string>() : std::optional<std::string>(error.dump()))
      .bind(6, listed)
      .run();
}

void Store::add_measurement(const std::string& run_id, const std::string& step, const std::string& instrument_id,
                            bool simulated, const std::string& quantity, std::optional<double> value,
                            const std::string& unit, const nlohmann::json& data) {
  Transaction tx(db_);
  std::int64_t seq = 0;
  {
    auto st = db_.prepare("SELECT COALESCE(MAX(seq), 0) + 1 FROM measurements WHERE run_id = ?1");
    st.bind(1, std::string_view(run_id));
    if (st.step()) seq = st.int64(0);
  }
  auto ins = db_.prepare(
      "INSERT INTO measurements (run_id, seq, step, instrument_id, simulated, quantity, value, unit, data, measured_at) "
      "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10)");
  ins.bind(1, std::string_view(run_id))
      .bind(2, seq)
      .bind(3, std::string_view(step))
      .bind(4, std::string_view(instrument_id))
      .bind(5, static_cast<std::int64_t>(simulated))
      .bind(6, std::string_view(quantity));
  if (value && std::isfinite(*value)) {
    ins.bind(7, *value);
  } else {
    ins.bind_null(7);
  }
  ins.bind(8, std::string_view(unit)).bind(9, std::string_view(dump_or_empty(data))).bind(10, std::string_view(now_iso8601()));
  ins.run();
  tx.commit();
}

bool Store::has_measurement(const std::string& run_id, const std::string& step) {
  auto st = db_.prepare("SELECT 1 FROM measurements WHERE run_id = ?1 AND step = ?2");
  st.bind(1, std::string_view(run_id)).bind(2, std::string_view(step));
  return st.step();
}

std::optional<ExecutionRecord> Store::execution(const std::string& id) {
  auto st = db_.prepare(std::string("SELECT ") + kExecutionColumns + " FROM executions WHERE id = ?1");
  st.bind(1, std::string_view(id));
  if (!st.step()) return std::nullopt;
  return read_execution(st);
}

std::optional<ExecutionRecord> Store::execution_with_idempotency_key(const std::string& key) {
  auto st = db_.prepare(std::string("SELECT ") + kExecutionColumns + " FROM executions WHERE idempotency_key = ?1");
  st.bind(1, std::string_view(key));
  if (!st.step()) return std::nullopt;
  return read_execution(st);
}

RunRecord Store::read_run(Statement& st) {
  RunRecord r;
  r.seq = st.int64(0);
  r.id = st.text(1);
  r.campaign = st.text(2);
  r.params = parse_json_column(st.text(3));
  r.status = st.text(4);
  r.simulated = st.int64(5) != 0;
  r.instruments = parse_json_column(st.text(6));
  r.created_at = st.text(7);
  if (!st.is_null(8)) r.started_at = st.text(8);
  if (!st.is_null(9)) r.finished_at = st.text(9);
  r.summary = parse_json_column(st.text(10));
  r.error = parse_json_column(st.text(11));
  if (!st.is_null(12)) r.script_sha256 = st.text(12);
  return r;
}

static constexpr const char* kRunColumns =
    "seq, id, campaign, params, status, simulated, instruments, created_at, started_at, finished_at, summary, error, "
    "script_sha256";
// The list's: the same fields, the summary without the script's result (schema 7 -> 8).
static constexpr const char* kRunListColumns =
    "seq, id, campaign, params, status, simulated, instruments, created_at, started_at, finished_at, list_summary, error, "
    "script_sha256";

std::optional<RunRecord> Store::run(const std::string& id) {
  auto st = db_.prepare(std::string("SELECT ") + kRunColumns + " FROM runs WHERE id = ?1");
  st.bind(1, std::string_view(id));
  if (!st.step()) return std::nullopt;
  return read_run(st);
}

namespace {

MeasurementRecord read_measurement(Statement& st) {
  MeasurementRecord m;
  m.seq = st.int64(0);
  m.step = st.text(1);
  m.instrument_id = st.text(2);
  m.simulated = st.int64(3) != 0;
  m.quantity = st.text(4);
  if (!st.is_null(5)) m.value = st.real(5);
  m.unit = st.text(6);
  m.data = parse_json_column(st.text(7));
  m.measured_at = st.text(8);
  return m;
}

constexpr const char* kMeasurementColumns =
    "seq, step, instrument_id, simulated, quantity, value, unit, data, measured_at";

}  // namespace

std::vector<MeasurementRecord> Store::measurements(const std::string& run_id) {
  auto st = db_.prepare(std::string("SELECT ") + kMeasurementColumns + " FROM measurements WHERE run_id = ?1 ORDER BY seq");
  st.bind(1, std::string_view(run_id));
  std::vector<MeasurementRecord> out;
  while (st.step()) out.push_back(read_measurement(st));
  return out;
}

MeasurementPage Store::measurements_page(const std::string& run_id, const MeasurementFilter& filter,
                                         std::int64_t after_seq, unsigned limit) {
  // One row more than asked says whether another page follows. The (run_id, seq) index orders it;
  // the filters are checked on the rows it walks (a run holds at most some 10^5 of them).
  auto st = db_.prepare(std::string("SELECT ") + kMeasurementColumns +
                        " FROM measurements WHERE run_id = ?1 AND seq > ?2"
                        " AND (?3 = '' OR substr(step, 1, length(?3)) = ?3)"
                        " AND (?4 = '' OR quantity = ?4) AND (?5 = '' OR instrument_id = ?5)"
                        " ORDER BY seq LIMIT ?6");
  st.bind(1, std::string_view(run_id))
      .bind(2, after_seq)
      .bind(3, std::string_view(filter.step_prefix))
      .bind(4, std::string_view(filter.quantity))
      .bind(5, std::string_view(filter.instrument_id))
      .bind(6, static_cast<std::int64_t>(limit) + 1);
  MeasurementPage page;
  while (st.step()) page.items.push_back(read_measurement(st));
  if (page.items.size() > limit) {
    page.items.pop_back();
    page.next_after = page.items.back().seq;
  }
  return page;
}

std::int64_t Store::measurement_count(const std::string& run_id) {
  auto st = db_.prepare("SELECT count(*) FROM measurements WHERE run_id = ?1");
  st.bind(1, std::string_view(run_id));
  return st.step() ? st.int64(0) : 0;
}

std::int64_t Store::last_event_seq() {
  auto st = db_.prepare("SELECT coalesce(max(seq), 0) FROM event_log");
  return st.step() ? st.int64(0) : 0;
}

namespace {

// A list's cursor: the seq (or rowid) the next page continues below.
std::int64_t cursor_before(const std::optional<std::string>& cursor) {
  if (!cursor) return INT64_MAX;
  try {
    std::size_t used = 0;
    std::int64_t before = std::stoll(*cursor, &used);
    if (used != cursor->size() || before <= 0) throw std::invalid_argument("cursor");
    return before;
  } catch (const std::exception&) {
    throw Error(ErrorClass::bad_parameter, "cursor '" + *cursor + "' is not a cursor this server issued",
                "use links.next from the previous page");
  }
}

}  // namespace

std::string run_list_sql(const RunFilter& filter) {
  // Keyset paging on seq (the rowid): a page's cost does not grow with how far back it is. A filter is
  // a plain equality (never "?3 = '' OR ..."), so SQLite can walk runs_by_campaign or runs_by_status.
  std::string sql = std::string("SELECT ") + kRunListColumns + " FROM runs WHERE seq < ?1";
  if (!filter.campaign.empty()) sql += " AND campaign = ?3";
  if (!filter.status.empty()) sql += " AND status = ?4";
  return sql + " ORDER BY seq DESC LIMIT ?2";
}

RunPage Store::runs(unsigned limit, const std::optional<std::string>& cursor, const RunFilter& filter) {
  std::int64_t before = cursor_before(cursor);
  auto st = db_.prepare(run_list_sql(filter));
  st.bind(1, before).bind(2, static_cast<std::int64_t>(limit) + 1);
  if (!filter.campaign.empty()) st.bind(3, std::string_view(filter.campaign));
  if (!filter.status.empty()) st.bind(4, std::string_view(filter.status));
  RunPage page;
  while (st.step()) page.runs.push_back(read_run(st));
  if (page.runs.size() > limit) {
    page.runs.pop_back();
    page.next_cursor = std::to_string(page.runs.back().seq);
  }
  return page;
}

ExecutionPage Store::executions(unsigned limit, const std::optional<std::string>& cursor, const ExecutionFilter& filter) {
  std::int64_t before = cursor_before(cursor);
  // The rowid is the table's insertion order (nothing here ever VACUUMs or reuses it): keyset paging
  // on the table's own b-tree, so a page costs the same however far back it is.
  std::string sql = std::string("SELECT ") + kExecutionColumns +
                    ", rowid FROM executions WHERE rowid < ?1 AND (?3 = '' OR campaign = ?3)";
  if (!filter.statuses.empty()) {
    sql += " AND status IN (";
    for (std::size_t i = 0; i < filter.statuses.size(); ++i) sql += (i ? ", ?" : "?") + std::to_string(4 + i);
    sql += ")";
  }
  sql += " ORDER BY rowid DESC LIMIT ?2";
  auto st = db_.prepare(sql);
  st.bind(1, before).bind(2, static_cast<std::int64_t>(limit) + 1).bind(3, std::string_view(filter.campaign));
  for (std::size_t i = 0; i < filter.statuses.size(); ++i)
    st.bind(static_cast<int>(4 + i), protocol::to_string(filter.statuses[i]));
  ExecutionPage page;
  std::vector<std::int64_t> rowids;
  while (st.step()) {
    page.items.push_back(read_execution(st));
    rowids.push_back(st.int64(15));
  }
  if (page.items.size() > limit) {
    page.items.pop_back();
    page.next_cursor = std::to_string(rowids[limit - 1]);
  }
  return page;
}

std::int64_t Store::append_event(const std::string& topic, const nlohmann::json& payload) {
  db_.prepare("INSERT INTO event_log (time, topic, payload) VALUES (?1, ?2, ?3)")
      .bind(1, std::string_view(now_iso8601()))
      .bind(2, std::string_view(topic))
      .bind(3, std::string_view(payload.dump()))
      .run();
  return db_.last_insert_rowid();
}

std::vector<EventRecord> Store::events(std::int64_t after, unsigned limit, const std::optional<std::string>& topic) {
  auto st = db_.prepare(
      "SELECT seq, time, topic, payload FROM event_log WHERE seq > ?1 AND (?2 IS NULL OR topic = ?2) ORDER BY seq LIMIT ?3");
  st.bind(1, after).bind(2, topic).bind(3, static_cast<std::int64_t>(limit));
  std::vector<EventRecord> out;
  while (st.step()) out.push_back(EventRecord{st.int64(0), st.text(1), st.text(2), parse_json_column(st.text(3))});
  return out;
}

}  // namespace colorlab::store
