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

void checkpoint_passive_on(sqlite3* db, WalHookState* state) noexcept {
  if (state) ++state->checkpoints;
  const auto start = std::chrono::steady_clock::now();
  int log_frames = 0, checkpointed = 0;
  // PASSIVE never calls the busy handler: what a reader still needs is left for the next checkpoint.
  const int rc = sqlite3_wal_checkpoint_v2(db, nullptr, SQLITE_CHECKPOINT_PASSIVE, &log_frames, &checkpointed);
  const std::chrono::duration<double, std::milli> took = std::chrono::steady_clock::now() - start;
  if (rc != SQLITE_OK && rc != SQLITE_BUSY) {
    log::warning("store", std::string("cannot checkpoint the WAL: ") + sqlite3_errstr(rc) + "; tried again later");
  } else if (took >= kLongCheckpoint) {
    char thread[16] = "?";
    pthread_getname_np(pthread_self(), thread, sizeof thread);
    log::info("store", "a checkpoint of the WAL (" + std::to_string(checkpointed) + " of " + std::to_string(log_frames) +
                           " pages) took " + std::to_string(std::lround(took.count())) + " ms (thread " + thread +
                           "); writers were not held");
  }
}

// SQLite calls this after each commit on the connection, the commit durable and the write lock released. An error
// returned would fail the COMMIT statement that already succeeded, so it always answers SQLITE_OK.
int after_commit(void* state_ptr, sqlite3* db, const char* /*schema*/, int wal_pages) {
  auto* state = static_cast<WalHookState*>(state_ptr);
  state->last_commit = std::chrono::steady_clock::now();
  ++state->commits;
  if (wal_pages < kWalAutocheckpointPages) return SQLITE_OK;
  if (state->checkpoint_elsewhere) {
    try {
      state->checkpoint_elsewhere();
    } catch (...) {
      // Asked again after the next commit; the WAL meanwhile grows toward bound_wal()'s limit at most.
    }
  } else {
    checkpoint_passive_on(db, state);
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

void checkpoint_passive(Database& db) noexcept { checkpoint_passive_on(db.handle(), db.wal_hook_state()); }

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
