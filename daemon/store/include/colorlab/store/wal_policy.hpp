#pragma once
// How large the writer's write-ahead log may grow (docs/configuration.md, "Disk use: the WAL and the logs").
// SQLite checkpoints the WAL into the database once it holds kWalAutocheckpointPages pages and, when a
// writer next starts from the WAL's beginning, truncates the file to kJournalSizeLimitBytes. A reader
// that is always mid-read (a console polling, an event stream) can keep the writer from ever starting
// over, and then the WAL grows with every commit: bound_wal() notices the file over its limit after a
// commit and checkpoints with RESTART, so the next commit starts over once those readers are done.
#include <cstdint>
#include <filesystem>

#include "colorlab/store/sqlite.hpp"

namespace colorlab::store {

inline constexpr int kWalAutocheckpointPages = 1000;                      // 4 MiB at SQLite's 4 KiB pages
inline constexpr std::int64_t kJournalSizeLimitBytes = 16 * 1024 * 1024;  // the WAL's size once reset

// The writer connection's WAL settings (journal_mode itself is set by the store).
void apply_wal_policy(Database& db);
// After a commit: a WAL file past kJournalSizeLimitBytes is checkpointed with RESTART, without waiting for
// readers. Never throws: the commit before it has succeeded, and a checkpoint a reader or a full disk
// refuses is tried again after the next commit.
void bound_wal(Database& db) noexcept;
// The size of the database's -wal file (0 when there is none).
std::int64_t wal_bytes(const std::filesystem::path& database_path);

}  // namespace colorlab::store
