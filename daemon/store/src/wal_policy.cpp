#include "colorlab/store/wal_policy.hpp"

#include <pthread.h>
#include <sqlite3.h>

#include <chrono>
#include <cmath>
#include <string>

#include "colorlab/core/log.hpp"
#include "colorlab/store/busy_retry.hpp"

namespace colorlab::store {

namespace {

// As long as the API's target for an answer (issue 27): a thread held this long by a checkpoint is worth a line.
constexpr std::chrono::milliseconds kLongCheckpoint{50};

void checkpoint_passive_on(sqlite3* db, const char* schema, WalHookState* state) noexcept {
  const auto start = std::chrono::steady_clock::now();
  int wal_frames = 0, in_database = 0;
  // PASSIVE never calls the busy handler: what a reader still needs is left for the next checkpoint.
  const int rc = sqlite3_wal_checkpoint_v2(db, schema, SQLITE_CHECKPOINT_PASSIVE, &wal_frames, &in_database);
  const std::chrono::duration<double, std::milli> took = std::chrono::steady_clock::now() - start;
  // BUSY: another checkpoint runs; LOCKED: a statement of this connection is still stepping (SQLite's own hook
  // ignores both too). Either way the next commit past the threshold tries again.
  if (rc == SQLITE_BUSY || rc == SQLITE_LOCKED) return;
  if (rc != SQLITE_OK) {
    if (state && state->checkpoint_failures++ % 100 == 0) {
      log::warning("store", std::string("cannot checkpoint the WAL: ") + sqlite3_errmsg(db) + " (failure " +
                                std::to_string(state->checkpoint_failures) + " in a row); tried again after later commits");
    }
    return;
  }
  if (!state) return;
  if (state->checkpoint_failures > 0) {
    log::info("store", "the WAL is checkpointed again after " + std::to_string(state->checkpoint_failures) + " failures");
    state->checkpoint_failures = 0;
  }
  ++state->checkpoints;
  if (took >= kLongCheckpoint && wal_frames >= 0) {
    char thread[16] = "?";
    pthread_getname_np(pthread_self(), thread, sizeof thread);
    log::info("store", "a checkpoint of the WAL took " + std::to_string(std::lround(took.count())) + " ms (thread " +
                           thread + "; " + std::to_string(in_database) + " of " + std::to_string(wal_frames) +
                           " frames now in the database); other connections could write meanwhile");
  }
}

// SQLite calls this after each commit on the connection, the commit durable and the write lock released. An error
// returned would fail the COMMIT statement that already succeeded, so it always answers SQLITE_OK.
int after_commit(void* state_ptr, sqlite3* db, const char* schema, int wal_pages) {
  auto* state = static_cast<WalHookState*>(state_ptr);
  state->last_commit = std::chrono::steady_clock::now();
  ++state->commits;
  const bool long_hold = state->write_lock_since != std::chrono::steady_clock::time_point{} &&
                         state->last_commit - state->write_lock_since >= kLongWriteLockHold;
  // Only where it is wanted: an ATTACHed schema's second call of the hook in the same COMMIT must not wipe it.
  if (long_hold) state->account_at_release = this_thread_account();
  state->write_lock_since = {};
  if (wal_pages < kWalAutocheckpointPages) return SQLITE_OK;
  if (state->checkpoint_elsewhere) {
    try {
      state->checkpoint_elsewhere();
    } catch (...) {
      // Asked again after the next commit; the WAL meanwhile grows toward bound_wal()'s limit at most.
    }
  } else {
    checkpoint_passive_on(db, schema, state);
  }
  return SQLITE_OK;
}

}  // namespace

void apply_wal_policy(Database& db) {
  db.exec("PRAGMA journal_size_limit = " + std::to_string(kJournalSizeLimitBytes));
  auto state = std::make_unique<WalHookState>();
  // Replaces SQLite's default hook, which `PRAGMA wal_autocheckpoint` would install.
  sqlite3_wal_hook(db.handle(), &after_commit, state.get());
  db.keep_wal_hook_state(std::move(state));
}

void hand_checkpoints_elsewhere(Database& db, std::function<void()> ask) {
  if (auto* state = db.wal_hook_state()) state->checkpoint_elsewhere = std::move(ask);
}

void checkpoint_passive(Database& db) noexcept { checkpoint_passive_on(db.handle(), nullptr, db.wal_hook_state()); }

std::int64_t wal_bytes(const std::filesystem::path& database_path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(database_path.string() + "-wal", ec);
  return ec ? 0 : static_cast<std::int64_t>(size);
}

void bound_wal(Database& db) noexcept {
  const char* file = sqlite3_db_filename(db.handle(), "main");
  if (!file || !*file) return;  // an in-memory database has no WAL
  if (wal_bytes(file) <= kJournalSizeLimitBytes) return;
  int log_frames = 0, checkpointed = 0;
  // Without the busy handler: the writer runs on the daemon's io thread, which must not wait for a long
  // reader (an export); a checkpoint a reader prevents now is tried again after the next commit.
  never_wait_when_busy(db);
  const int rc = sqlite3_wal_checkpoint_v2(db.handle(), nullptr, SQLITE_CHECKPOINT_RESTART, &log_frames, &checkpointed);
  retry_promptly_when_busy(db, kBusyTimeout);
  if (rc != SQLITE_OK && rc != SQLITE_BUSY) {
    log::warning("store", std::string("cannot checkpoint the WAL past its limit: ") + sqlite3_errstr(rc));
  }
}

}  // namespace colorlab::store
