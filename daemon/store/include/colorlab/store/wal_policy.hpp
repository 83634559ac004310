#pragma once
// How large the writer's write-ahead log may grow (docs/configuration.md, "Disk use: the WAL and the logs").
// SQLite checkpoints the WAL into the database once it holds kWalAutocheckpointPages pages and, when a
// writer next starts from the WAL's beginning, truncates the file to kJournalSizeLimitBytes. A reader
// that is always mid-read (a console polling, an event stream) can keep the writer from ever starting
// over, and then the WAL grows with every commit: bound_wal() notices the file over its limit after a
// commit and checkpoints with RESTART, so the next commit starts over once those readers are done.
//
// The checkpoint at kWalAutocheckpointPages is the store's own WAL hook's rather than SQLite's
// (`PRAGMA wal_autocheckpoint`, which is the same PASSIVE checkpoint from a default hook): SQLite runs it inside
// the COMMIT call that crossed the threshold, on that thread — the copy of 4 MiB into the database and its fsync,
// over 100 ms on a busy disk — so a connection on colorlabd's io thread hands it to the step committer's thread
// instead (hand_checkpoints_elsewhere), and a Transaction times its hold of the lock to the commit's own end
// (bench/daemon/checkpoint_in_commit.py: other writers get the lock once the commit proper is done).
#include <cstdint>
#include <filesystem>
#include <functional>

#include "colorlab/store/sqlite.hpp"

namespace colorlab::store {

inline constexpr int kWalAutocheckpointPages = 1000;                      // 4 MiB at SQLite's 4 KiB pages
inline constexpr std::int64_t kJournalSizeLimitBytes = 16 * 1024 * 1024;  // the WAL's size once reset

// The writer connection's WAL settings (journal_mode itself is set by the store): the journal's size limit, and the
// WAL hook, which notes each commit (WalHookState) and, once the WAL holds kWalAutocheckpointPages pages,
// checkpoints it here (checkpoint_passive) or asks for it elsewhere.
void apply_wal_policy(Database& db);
// From now on this connection's commits never checkpoint; past the threshold they call `ask`, which must not block
// (empty: they checkpoint here again). Needs apply_wal_policy() first.
void hand_checkpoints_elsewhere(Database& db, std::function<void()> ask);
// A PASSIVE checkpoint now: copies into the database what no reader still needs, waiting for no reader or writer.
// Logged when it took 50 ms or more. Never throws: one a full disk refuses is asked for again after a later commit.
void checkpoint_passive(Database& db) noexcept;
// After a commit: a WAL file past kJournalSizeLimitBytes is checkpointed with RESTART, without waiting for
// readers. Never throws: the commit before it has succeeded, and a checkpoint a reader or a full disk
// refuses is tried again after the next commit.
void bound_wal(Database& db) noexcept;
// The size of the database's -wal file (0 when there is none).
std::int64_t wal_bytes(const std::filesystem::path& database_path);

}  // namespace colorlab::store
