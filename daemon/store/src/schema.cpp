#include "colorlab/store/schema.hpp"

#include <array>
#include <string>

#include "colorlab/core/error.hpp"

namespace colorlab::store {

namespace {

// migrations[i] takes the schema from version i to i + 1. Never edit a shipped entry; append.
constexpr std::array<const char*, kSchemaVersion> kMigrations = {
    // 0 -> 1: runs, their measurements, executions and the event log.
    R"sql(
CREATE TABLE runs (
  seq          INTEGER PRIMARY KEY AUTOINCREMENT,  -- cursor for paging, never reused
  id           TEXT NOT NULL UNIQUE,               -- UUIDv7
  campaign     TEXT NOT NULL,
  params       TEXT NOT NULL,                      -- JSON
  status       TEXT NOT NULL,
  simulated    INTEGER NOT NULL,                   -- 1 if any instrument was simulated
  instruments  TEXT NOT NULL,                      -- JSON snapshot of the instruments used
  created_at   TEXT NOT NULL,
  started_at   TEXT,
  finished_at  TEXT,
  summary      TEXT,                               -- JSON
  error        TEXT                                -- JSON problem
);
CREATE TABLE measurements (
  run_id        TEXT NOT NULL REFERENCES runs(id),
  seq           INTEGER NOT NULL,
  step          TEXT NOT NULL,
  instrument_id TEXT NOT NULL,
  simulated     INTEGER NOT NULL,
  quantity      TEXT NOT NULL,
  value         REAL,
  unit          TEXT,
  data          TEXT,                              -- JSON
  measured_at   TEXT NOT NULL,
  PRIMARY KEY (run_id, step)
) WITHOUT ROWID;
CREATE INDEX measurements_by_seq ON measurements(run_id, seq);
CREATE TABLE executions (
  id              TEXT PRIMARY KEY,
  run_id          TEXT NOT NULL REFERENCES runs(id),
  campaign        TEXT NOT NULL,
  status          TEXT NOT NULL,
  progress        REAL NOT NULL DEFAULT 0,
  step            TEXT NOT NULL DEFAULT '',
  idempotency_key TEXT UNIQUE,
  created_at      TEXT NOT NULL,
  updated_at      TEXT NOT NULL,
  error           TEXT
);
CREATE TABLE event_log (
  seq     INTEGER PRIMARY KEY AUTOINCREMENT,
  time    TEXT NOT NULL,
  topic   TEXT NOT NULL,
  payload TEXT NOT NULL
);
)sql",
    // 1 -> 2: campaign scripts stored with their runs, the journal of lab calls that makes an
    // execution resumable by replay, and the execution's reason and resume attempts.
    R"sql(
CREATE TABLE scripts (
  sha256      TEXT PRIMARY KEY,                    -- of the exact text that ran
  name        TEXT NOT NULL,
  source      TEXT NOT NULL,
  first_seen  TEXT NOT NULL
);
ALTER TABLE runs ADD COLUMN script_sha256 TEXT REFERENCES scripts(sha256);
ALTER TABLE executions ADD COLUMN script_sha256 TEXT REFERENCES scripts(sha256);
ALTER TABLE executions ADD COLUMN random_seed INTEGER NOT NULL DEFAULT 0;
ALTER TABLE executions ADD COLUMN reason TEXT NOT NULL DEFAULT '';
ALTER TABLE executions ADD COLUMN resume_attempts INTEGER NOT NULL DEFAULT 0;
ALTER TABLE executions ADD COLUMN steps_committed INTEGER NOT NULL DEFAULT 0;
CREATE TABLE journal (
  execution_id TEXT NOT NULL REFERENCES executions(id),
  seq          INTEGER NOT NULL,                   -- position of the lab call in the script's run
  call         TEXT NOT NULL,
  args         TEXT NOT NULL,                      -- JSON
  result       TEXT NOT NULL,                      -- JSON
  at           TEXT NOT NULL,
  PRIMARY KEY (execution_id, seq)
) WITHOUT ROWID;
CREATE INDEX executions_unfinished ON executions(status) WHERE status IN ('waiting', 'running', 'paused', 'suspended');
)sql",
    // 2 -> 3: the night's queue: executions waiting their turn, each with its on-failure policy,
    // and whether the queue runs (one row), so both outlive the daemon.
    R"sql(
CREATE TABLE queue_items (
  id              TEXT PRIMARY KEY,                -- UUIDv7
  position        INTEGER,                         -- 1..N among the queued items; NULL once it left the queue
  campaign        TEXT NOT NULL,
  params          TEXT NOT NULL,                   -- JSON, validated at enqueue, defaults filled in
  on_failure      TEXT NOT NULL CHECK (on_failure IN ('stop', 'continue')),
  state           TEXT NOT NULL CHECK (state IN ('queued', 'running', 'done', 'failed', 'skipped', 'removed')),
  execution_id    TEXT REFERENCES executions(id),  -- once started
  reason          TEXT NOT NULL DEFAULT '',        -- why it failed, was skipped or removed
  idempotency_key TEXT UNIQUE,                     -- a retried enqueue returns the same item
  created_at      TEXT NOT NULL,
  updated_at      TEXT NOT NULL,
  started_at      TEXT,
  finished_at     TEXT
);
CREATE INDEX queue_items_pending ON queue_items(state, position) WHERE state IN ('queued', 'running');
CREATE TABLE queue_state (
  id          INTEGER PRIMARY KEY CHECK (id = 1),  -- exactly one row
  started     INTEGER NOT NULL,                    -- 1: starts the next item whenever the lab is free
  halted      INTEGER NOT NULL,                    -- 1: an item failed with on_failure = stop
  reason      TEXT NOT NULL,                       -- why it stopped
  updated_at  TEXT NOT NULL
);
INSERT INTO queue_state (id, started, halted, reason, updated_at)
  VALUES (1, 0, 0, '', strftime('%Y-%m-%dT%H:%M:%fZ', 'now'));
)sql",
    // 3 -> 4: how long each kind of lab call takes on this lab, learned from live calls, so a dry
    // run can estimate a campaign's duration from the instruments' own timings. Per time scale:
    // the simulated lab's seconds shrink, the daemon's own time does not.
    R"sql(
CREATE TABLE call_timings (
  key         TEXT NOT NULL,                       -- e.g. "meter.measure", "wait_stable cold D65"
  time_scale  REAL NOT NULL,                       -- lab seconds per wall second when measured
  n           INTEGER NOT NULL,
  sum_s       REAL NOT NULL,                       -- lab seconds per unit, summed
  sum_sq      REAL NOT NULL,
  updated_at  TEXT NOT NULL,
  PRIMARY KEY (key, time_scale)
) WITHOUT ROWID;
)sql",
    // 4 -> 5: the data service. Frames kept as content-addressed files under the state directory
    // (the file is named by its SHA-256 and written before the row that references it), which run
    // and step each belongs to; and the API keys for listeners beyond loopback, stored as hashes.
    R"sql(
CREATE TABLE blobs (
  sha256      TEXT PRIMARY KEY,                    -- of the file's bytes; also its name in the blob store
  size        INTEGER NOT NULL,
  media_type  TEXT NOT NULL,                       -- e.g. image/x-adobe-dng, image/tiff, application/x-colorlab-array
  meta        TEXT NOT NULL DEFAULT '{}',          -- JSON: dtype, shape, cfa for raw arrays; width, height, bits
  created_at  TEXT NOT NULL
) WITHOUT ROWID;
CREATE TABLE run_blobs (
  run_id      TEXT NOT NULL REFERENCES runs(id),
  name        TEXT NOT NULL,                       -- unique within the run, e.g. "D65/frame-average"
  sha256      TEXT NOT NULL REFERENCES blobs(sha256),
  step        TEXT NOT NULL,                       -- the step that captured it
  kind        TEXT NOT NULL,                       -- raw, dng, average, tiff16, tiff8, jpeg, preview
  created_at  TEXT NOT NULL,
  PRIMARY KEY (run_id, name)
) WITHOUT ROWID;
CREATE INDEX run_blobs_by_sha ON run_blobs(sha256);
CREATE TABLE api_keys (
  id            TEXT PRIMARY KEY,                  -- UUIDv7; names the key in lists and logs, not secret
  name          TEXT NOT NULL,                     -- who or what holds it
  scope         TEXT NOT NULL CHECK (scope IN ('read', 'control', 'admin')),
  secret_sha256 TEXT NOT NULL UNIQUE,              -- SHA-256 of the whole key; the key itself is never stored
  created_at    TEXT NOT NULL,
  last_used_at  TEXT,
  revoked_at    TEXT
);
)sql",
    // 5 -> 6: queue items that take an earlier item's run, and sequences queued as one group. An item's
    // params may hold {"$run_of": "<item id>"} for a parameter; param_refs keeps parameter -> item id
    // (the params get the run id written in when the item comes up, so a restarted daemon starts the
    // same thing). A group is one sequence's items, queued together; step names the item within it.
    R"sql(
ALTER TABLE queue_items ADD COLUMN param_refs TEXT NOT NULL DEFAULT '{}';
ALTER TABLE queue_items ADD COLUMN group_id TEXT;
ALTER TABLE queue_items ADD COLUMN step TEXT;
CREATE INDEX queue_items_by_group ON queue_items(group_id) WHERE group_id IS NOT NULL;
CREATE TABLE queue_groups (
  id          TEXT PRIMARY KEY,                    -- UUIDv7
  sequence    TEXT NOT NULL,                       -- the catalogue's sequence it was queued from
  options     TEXT NOT NULL DEFAULT '{}',          -- JSON: small, overrides, on_failure as asked
  created_at  TEXT NOT NULL
);
)sql",
    // 6 -> 7: why a suspended execution waits, as JSON ({category, problem, ...}; the crash-loop guard adds its
    // back-off: attempt, retries, backoff_s, retry_at), so a restarted daemon keeps the guard's schedule and
    // every client sees the cause. NULL whenever the execution is not suspended.
    R"sql(
ALTER TABLE executions ADD COLUMN suspension TEXT;
)sql",
    // 7 -> 8: GET /v1/runs costs the same however many runs are kept (issue 27). The list reads a run's
    // summary without the campaign script's own result (list_summary), which can be far larger than the
    // rest of the row and was parsed and re-serialised for every listed run; and a filtered list walks an
    // index of its campaign or status (newest first) instead of every run.
    R"sql(
ALTER TABLE runs ADD COLUMN list_summary TEXT;  -- JSON: summary without "script" (GET /v1/runs/{id} has that)
UPDATE runs SET list_summary = json_remove(summary, '$.script') WHERE summary IS NOT NULL AND json_valid(summary);
CREATE INDEX runs_by_campaign ON runs(campaign, seq);
CREATE INDEX runs_by_status ON runs(status, seq);
)sql",
};

int read_pragma_int(Database& db, const char* pragma) {
  auto st = db.prepare(std::string("PRAGMA ") + pragma);
  return st.step() ? static_cast<int>(st.int64(0)) : 0;
}

}  // namespace

int schema_version(Database& db) { return read_pragma_int(db, "user_version"); }

void migrate(Database& db) {
  int version = schema_version(db);
  int app_id = read_pragma_int(db, "application_id");
  if (app_id != 0 && app_id != kApplicationId) {
    throw Error(ErrorClass::io_error,
                "the database file belongs to another application (application_id " +
                    std::to_string(app_id) + ")",
                "point --state at colorlab's own state directory");
  }
  if (version > kSchemaVersion) {
    throw Error(ErrorClass::io_error,
                "the database has schema version " + std::to_string(version) + ", newer than this colorlabd (" +
                    std::to_string(kSchemaVersion) + ")",
                "run a newer colorlabd; an older binary must not write a newer database");
  }
  for (int v = version; v < kSchemaVersion; ++v) {
    Transaction tx(db);
    db.exec(kMigrations[v]);
    db.exec("PRAGMA user_version = " + std::to_string(v + 1));
    db.exec("PRAGMA application_id = " + std::to_string(kApplicationId));
    tx.commit();
  }
}

}  // namespace colorlab::store
