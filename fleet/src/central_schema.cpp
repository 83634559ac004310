#include "colorlab/fleet/central_schema.hpp"

#include <array>
#include <string>

#include "colorlab/core/error.hpp"

namespace colorlab::fleet {

namespace {

// kMigrations[i] takes the schema from version i to i + 1. Never edit a shipped entry; append.
// Text columns keep the bench's exact text (JSON documents, ISO 8601 times) and REAL is double precision, so the
// per-run digest (digest.hpp) is the same bytes on both sides; typed views can come later without losing that.
constexpr std::array<const char*, kCentralSchemaVersion> kMigrations = {
    R"sql(
CREATE TABLE benches (
  id               text PRIMARY KEY,            -- [ship] bench_id
  name             text NOT NULL,
  software_version text NOT NULL,
  bench_schema     integer NOT NULL,            -- the bench's SQLite schema version
  first_seen       timestamptz NOT NULL DEFAULT now(),
  last_seen        timestamptz NOT NULL DEFAULT now(),
  shipped_position bigint NOT NULL DEFAULT 0,   -- the bench's event_log seq shipped up to, inclusive
  last_error       text
);
CREATE TABLE runs (
  id            text PRIMARY KEY,               -- UUIDv7, global
  bench_id      text NOT NULL REFERENCES benches(id),
  bench_seq     bigint NOT NULL,                -- the run's seq on its bench
  campaign      text NOT NULL,
  params        text NOT NULL,
  status        text NOT NULL,                  -- finished_ok, finished_error, aborted or interrupted
  simulated     integer NOT NULL,
  instruments   text NOT NULL,
  created_at    text NOT NULL,
  started_at    text,
  finished_at   text,
  summary       text,
  error         text,
  script_sha256 text,
  ended_event   bigint NOT NULL,                -- the bench's event that ended it
  shipped_at    timestamptz NOT NULL DEFAULT now()
);
CREATE INDEX runs_by_bench ON runs (bench_id, bench_seq);
CREATE TABLE executions (
  id          text PRIMARY KEY,
  run_id      text NOT NULL REFERENCES runs(id),
  campaign    text NOT NULL,
  status      text NOT NULL,
  progress    double precision NOT NULL,
  step        text NOT NULL,
  created_at  text NOT NULL,
  updated_at  text NOT NULL,
  error       text,
  reason      text NOT NULL,
  steps_committed bigint NOT NULL
);
CREATE TABLE measurements (
  run_id        text NOT NULL REFERENCES runs(id),
  step          text NOT NULL,
  seq           bigint NOT NULL,
  instrument_id text NOT NULL,
  simulated     integer NOT NULL,
  quantity      text NOT NULL,
  value         double precision,
  unit          text,
  data          text,
  measured_at   text NOT NULL,
  PRIMARY KEY (run_id, step)
);
CREATE TABLE blobs (
  sha256      text PRIMARY KEY,                 -- also the object's key: sha256/<hex>
  size        bigint NOT NULL,
  media_type  text NOT NULL,
  meta        text NOT NULL
);
CREATE TABLE run_blobs (
  run_id      text NOT NULL REFERENCES runs(id),
  name        text NOT NULL,
  sha256      text NOT NULL REFERENCES blobs(sha256),
  step        text NOT NULL,
  kind        text NOT NULL,
  created_at  text NOT NULL,
  PRIMARY KEY (run_id, name)
);
CREATE TABLE events (
  bench_id    text NOT NULL REFERENCES benches(id),
  seq         bigint NOT NULL,
  time        text NOT NULL,
  topic       text NOT NULL,
  payload     text NOT NULL,
  PRIMARY KEY (bench_id, seq)
);
-- What went wrong while shipping (a digest mismatch above all), for people and the future central API.
CREATE TABLE ship_problems (
  id          bigserial PRIMARY KEY,
  bench_id    text NOT NULL,
  run_id      text,
  kind        text NOT NULL,                    -- digest_mismatch
  detail      text NOT NULL,
  at          timestamptz NOT NULL DEFAULT now()
);
)sql",
    // 2: what colorlab-central reads. Each bench's backlog as its agent last saw it (GET /v1/benches shows the
    // lag: the oldest ended run not yet shipped and its age); keyset orders for the run list (newest first by
    // UUIDv7, which orders across benches by creation time) under each filter; measurements by seq.
    R"sql(
ALTER TABLE benches
  ADD COLUMN backlog_runs           integer,      -- ended runs the bench held unshipped at backlog_at
  ADD COLUMN oldest_unshipped_run   text,         -- the oldest of them (null: none)
  ADD COLUMN oldest_unshipped_ended timestamptz,  -- when it ended, by the bench's clock
  ADD COLUMN backlog_at             timestamptz;  -- when the agent last counted (central's clock)
CREATE INDEX runs_by_bench_id    ON runs (bench_id, id);
CREATE INDEX runs_by_campaign_id ON runs (campaign, id);
CREATE INDEX runs_by_status_id   ON runs (status, id);
CREATE INDEX measurements_by_seq ON measurements (run_id, seq);
)sql",
};

constexpr const char* kLock = "SELECT pg_advisory_xact_lock(7336021)";  // "colorlab central schema"

}  // namespace

int central_schema_version(Pg& pg) {
  auto exists = pg.query("SELECT to_regclass('schema_migrations') IS NOT NULL");
  if (exists.text(0, 0) != "t") return 0;
  auto v = pg.query("SELECT coalesce(max(version), 0) FROM schema_migrations");
  return static_cast<int>(v.int64(0, 0));
}

void central_migrate(Pg& pg) {
  pg.exec("BEGIN");
  try {
    pg.exec(kLock);
    pg.exec("CREATE TABLE IF NOT EXISTS schema_migrations (version integer PRIMARY KEY, "
            "applied_at timestamptz NOT NULL DEFAULT now())");
    pg.exec("COMMIT");
  } catch (...) {
    try {
      pg.exec("ROLLBACK");
    } catch (...) {
    }
    throw;
  }
  for (;;) {
    pg.exec("BEGIN");
    try {
      pg.exec(kLock);
      const int v = central_schema_version(pg);
      if (v > kCentralSchemaVersion) {
        throw Error(ErrorClass::conflict,
                    "the central schema is version " + std::to_string(v) + ", newer than this colorlab-ship (" +
                        std::to_string(kCentralSchemaVersion) + ")",
                    "upgrade colorlab on this machine; never downgrade the central schema");
      }
      if (v == kCentralSchemaVersion) {
        pg.exec("COMMIT");
        return;
      }
      pg.exec(kMigrations[static_cast<std::size_t>(v)]);
      pg.query("INSERT INTO schema_migrations (version) VALUES ($1)", {std::to_string(v + 1)});
      pg.exec("COMMIT");
    } catch (...) {
      try {
        pg.exec("ROLLBACK");
      } catch (...) {
      }
      throw;
    }
  }
}

void central_require(Pg& pg) {
  int v = central_schema_version(pg);
  // Only a database without colorlab's tables is set up implicitly; one that has them but lacks their migration
  // rows is an older central, which only `central-init` may touch.
  if (v == 0 && pg.query("SELECT to_regclass('benches') IS NULL").text(0, 0) == "t") {
    central_migrate(pg);
    v = central_schema_version(pg);
  }
  if (v < kCentralSchemaVersion) {
    throw Error(ErrorClass::conflict,
                "this bench's colorlab-ship writes central schema version " + std::to_string(kCentralSchemaVersion) +
                    " but the central PostgreSQL holds version " + std::to_string(v),
                "upgrade the central schema first: run `colorlab-ship central-init --config <toml>` with the new "
                "colorlab (it migrates in place; older benches must then be upgraded too)");
  }
  if (v > kCentralSchemaVersion) {
    throw Error(ErrorClass::conflict,
                "the central schema is version " + std::to_string(v) + ", newer than this bench's colorlab-ship (" +
                    std::to_string(kCentralSchemaVersion) + ")",
                "upgrade colorlab on this bench to the version that set up the central schema");
  }
}

}  // namespace colorlab::fleet
