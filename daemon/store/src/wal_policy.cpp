#include "colorlab/store/wal_policy.hpp"

#include <sqlite3.h>

#include <string>

#include "colorlab/core/log.hpp"
#include "colorlab/store/busy_retry.hpp"

namespace colorlab::store {

void apply_wal_policy(Database& db) {
  db.exec("PRAGMA wal_autocheckpoint = " + std::to_string(kWalAutocheckpointPages));
  db.exec("PRAGMA journal_size_limit = " + std::to_string(kJournalSizeLimitBytes));
}

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
