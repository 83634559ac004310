#pragma once
// The daemon's persistent state. One writer connection, used from the daemon's event loop only — and a
// second (SecondWriter, below) on the step committer's thread, for campaign steps' commits (issue 27).
// Settings follow daemon-design-notes §6.2: WAL, synchronous=FULL (a committed measurement
// survives power loss), busy_timeout, foreign keys, quick_check at open.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/core/step_records.hpp"
#include "colorlab/protocol/states.hpp"
#include "colorlab/store/sqlite.hpp"
#include "colorlab/store/step_blob.hpp"

namespace colorlab::store {

struct NewRun {
  std::string campaign;
  nlohmann::json params;
  bool simulated = false;
  nlohmann::json instruments;  // snapshot
  std::optional<std::string> idempotency_key;
  // The exact script text that runs (stored once per hash) and the seed its math.random draws from.
  std::string script_sha256;
  std::string script_source;
  std::uint64_t random_seed = 0;
};

struct ExecutionRecord {
  std::string id;
  std::string run_id;
  std::string campaign;
  protocol::ExecutionStatus status = protocol::ExecutionStatus::waiting;
  double progress = 0;
  std::string step;
  std::string created_at;
  std::string updated_at;
  nlohmann::json error;  // problem, or null
  std::string reason;    // why it is paused, suspended, aborted or ended
  // While suspended: {category, problem, ...} (the crash-loop guard adds its back-off); null otherwise.
  nlohmann::json suspension;
  int resume_attempts = 0;
  std::int64_t steps_committed = 0;
  std::string script_sha256;
  std::uint64_t random_seed = 0;
  nlohmann::json to_json() const;
};

// A step's records are the engine's as it hands them over (colorlab/core/step_records.hpp): the
// journal entry, the call's timing (lab seconds per unit under the key campaigns::TimingKeys gave it).
using JournalRow = records::JournalEntry;
using CallTimingRow = records::CallTiming;

struct LearnedTiming {
  std::int64_t n = 0;
  double mean_s = 0;
  double stdev_s = 0;
  double time_scale = 1;  // the time scale it was learned at
};

using MeasurementRow = records::Measurement;

// One committed step of a campaign: its journal entries, its measurements and its progress.
struct StepRecord {
  std::vector<JournalRow> journal;
  std::vector<MeasurementRow> measurements;
  double progress = 0;
  std::string step;
  // When set, replaces the run's instrument snapshot in the same transaction (serials learned
  // once the instruments connected).
  std::optional<nlohmann::json> instruments;
  // How long the step's live calls took, learned in the same transaction (see CallTimingRow).
  std::vector<CallTimingRow> timings;
  double time_scale = 1;
  // Frames the step kept: their files are already durable; their rows are the step's (blob_index.hpp).
  std::vector<StepBlob> blobs;
};

struct MeasurementRecord {
  std::int64_t seq = 0;
  std::string step;
  std::string instrument_id;
  bool simulated = false;
  std::string quantity;
  std::optional<double> value;
  std::string unit;
  nlohmann::json data;
  std::string measured_at;
  nlohmann::json to_json() const;
};

struct RunRecord {
  std::int64_t seq = 0;
  std::string id;
  std::string campaign;
  nlohmann::json params;
  std::string status;
  bool simulated = false;
  nlohmann::json instruments;
  std::string created_at;
  std::optional<std::string> started_at, finished_at;
  nlohmann::json summary;
  nlohmann::json error;
  std::string script_sha256;
  nlohmann::json to_json() const;  // without measurements
};

struct EventRecord {
  std::int64_t seq = 0;
  std::string time;
  std::string topic;
  nlohmann::json payload;
};

// Which runs a page of GET /v1/runs holds; empty fields match everything.
struct RunFilter {
  std::string campaign;  // exact name
  std::string status;    // exact status
};

// The SQL of a page of GET /v1/runs (?1 the cursor, ?2 the limit, ?3 campaign, ?4 status when filtered):
// public so that a test can check its query plan.
std::string run_list_sql(const RunFilter& filter);

struct RunPage {
  std::vector<RunRecord> runs;
  std::optional<std::string> next_cursor;
};

// Which executions a page of GET /v1/executions holds; empty fields match everything.
struct ExecutionFilter {
  std::vector<protocol::ExecutionStatus> statuses;  // any of these
  std::string campaign;                             // exact name
};

struct ExecutionPage {
  std::vector<ExecutionRecord> items;
  std::optional<std::string> next_cursor;
};

// Which of a run's measurements a page holds; empty fields match everything.
struct MeasurementFilter {
  std::string step_prefix;
  std::string quantity;
  std::string instrument_id;
};

struct MeasurementPage {
  std::vector<MeasurementRecord> items;
  std::optional<std::int64_t> next_after;  // the seq to continue after, when more rows match
};

class Store {
 public:
  // Creates the directory and database as needed, migrates and checks integrity. Executions a
  // previous process left unfinished stay as they were, for the daemon to resume; only those
  // without a stored script (made before scripts were stored) are marked `interrupted`.
  explicit Store(const std::filesystem::path& database_path);
  // A reader's own connection to an existing database: never migrates, never writes
  // (query_only), and in WAL mode never waits for the writer's commits. One per reading thread.
  struct ReadOnly {};
  Store(const std::filesystem::path& database_path, ReadOnly);
  // A second writer's connection to a database the first Store has opened (migrated and checked): the
  // same durability (WAL, synchronous=FULL) and WAL bounds, for commit_step() on a thread of its own
  // (daemon/core step_committer.hpp). SQLite orders the two writers' transactions (BEGIN IMMEDIATE
  // waits up to the busy timeout), so the event log's seq is still the commit order.
  struct SecondWriter {};
  Store(const std::filesystem::path& database_path, SecondWriter);

  // The WAL's checkpoints (wal_policy.hpp): this connection's commits stop checkpointing it themselves and call
  // `ask` instead, which must not block; empty: they checkpoint again. colorlabd's io thread hands them to the step
  // committer (daemon/core step_committer.hpp), whose connection then runs them (checkpoint_wal). Call it on the
  // thread that uses this Store, or while that thread is not committing: the hook reads `ask` there.
  void hand_wal_checkpoints_to(std::function<void()> ask);
  // A PASSIVE checkpoint on this connection now. Never throws (logged; asked again after a later commit).
  void checkpoint_wal() noexcept;
  // How many checkpoints this connection has run to completion of their call (after its commits, or checkpoint_wal;
  // SQLITE_OK, whether or not a reader left frames uncopied); 0 for a reader's.
  std::uint64_t wal_checkpoints_run() const;

  // Creates a run and its execution in one transaction. With an idempotency key already used,
  // returns the existing execution and created = false (a retried POST must not start a campaign twice).
  struct Created {
    ExecutionRecord execution;
    bool created = false;
  };
  Created create_execution(const NewRun& run);
  void update_execution(const std::string& execution_id, protocol::ExecutionStatus status, double progress,
                        const std::string& step, const nlohmann::json& error = nullptr);
  void finish_run(const std::string& run_id, protocol::ExecutionStatus status, const nlohmann::json& summary,
                  const nlohmann::json& error);
  void mark_run_started(const std::string& run_id);

  // The execution's state changes, each one transaction (one fsync) so that the run, the
  // execution and the event log never disagree after a crash.
  void start_execution(const ExecutionRecord& execution);
  void report_progress(const std::string& execution_id, double progress, const std::string& step);
  void finish_execution(const ExecutionRecord& execution, protocol::ExecutionStatus status, const std::string& step,
                        const nlohmann::json& summary, const nlohmann::json& error, const std::string& reason = {});
  // paused / suspended / running again, with the run's status and an event, in one transaction.
  // `suspension` (why it waits, see ExecutionRecord) is stored with a suspended status, cleared otherwise,
  // and given in the event.
  void set_execution_status(const ExecutionRecord& execution, protocol::ExecutionStatus status, const std::string& reason,
                            const nlohmann::json& event_extra = nullptr, const nlohmann::json& suspension = nullptr);
  // A restart is about to resume this execution: counts the attempt (reset by the next committed
  // step) and returns how many resumes in a row have not committed a step.
  int begin_resume(const std::string& execution_id);
  // One campaign step in one transaction (one fsync): journal, measurements, progress and event.
  void commit_step(const ExecutionRecord& execution, const StepRecord& step);
  std::vector<JournalRow> journal(const std::string& execution_id);
  std::set<std::string> measurement_steps(const std::string& run_id);
  std::optional<std::string> script_source(const std::string& sha256);
  // What each kind of lab call has cost on this lab: per key, the figures learned at `time_scale`,
  // or at the nearest time scale where a key was never timed at this one.
  std::map<std::string, LearnedTiming> call_timings(double time_scale);
  // waiting, running, paused or suspended, oldest first.
  std::vector<ExecutionRecord> unfinished_executions();
  // Per quantity: count, unit, mean, stdev, min, max — computed by SQL from the stored rows.
  nlohmann::json measurement_summary(const std::string& run_id);

  // Durable on return (synchronous=FULL). A repeated step is refused with Error{conflict}.
  void add_measurement(const std::string& run_id, const std::string& step, const std::string& instrument_id,
                       bool simulated, const std::string& quantity, std::optional<double> value,
                       const std::string& unit, const nlohmann::json& data);
  bool has_measurement(const std::string& run_id, const std::string& step);

  std::optional<ExecutionRecord> execution(const std::string& id);
  // The execution a POST with this Idempotency-Key started, if one did.
  std::optional<ExecutionRecord> execution_with_idempotency_key(const std::string& key);
  std::optional<RunRecord> run(const std::string& id);
  std::vector<MeasurementRecord> measurements(const std::string& run_id);
  // Keyset page of a run's measurements in seq order, after `after_seq` (0: from the start).
  MeasurementPage measurements_page(const std::string& run_id, const MeasurementFilter& filter,
                                    std::int64_t after_seq, unsigned limit);
  std::int64_t measurement_count(const std::string& run_id);
  std::int64_t last_event_seq();
  // Reads on this connection in one snapshot of the database until it is dropped (sqlite.hpp's ReadTransaction):
  // what a second writer commits meanwhile is not seen, so e.g. an event stream's snapshot and its seq agree.
  [[nodiscard]] ReadTransaction read_snapshot() { return ReadTransaction(db_); }
  // Newest first; `cursor` is the opaque next_cursor of the previous page. A listed run's summary leaves
  // out "script" (the campaign's own result, unbounded in size); run(id) has the whole summary.
  RunPage runs(unsigned limit, const std::optional<std::string>& cursor, const RunFilter& filter = {});
  // Newest first (in the order they were created); `cursor` as for runs().
  ExecutionPage executions(unsigned limit, const std::optional<std::string>& cursor, const ExecutionFilter& filter = {});

  std::int64_t append_event(const std::string& topic, const nlohmann::json& payload);
  // Events with seq > after, oldest first (a client resumes from the last seq it saw).
  std::vector<EventRecord> events(std::int64_t after, unsigned limit, const std::optional<std::string>& topic);
  int interrupted_at_open() const { return interrupted_at_open_; }

 private:
  // The queue's rows live in their own file and share this connection (one writer, one thread).
  friend class QueueStore;
  friend class BlobIndex;    // blob_index.hpp: the blob store's rows
  friend class ApiKeyStore;  // api_keys.hpp: keys on the same writer connection
  RunRecord read_run(Statement& st);
  ExecutionRecord read_execution(Statement& st);

  Database db_;
  int interrupted_at_open_ = 0;
};

}  // namespace colorlab::store
