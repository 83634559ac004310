#pragma once
// A thin RAII layer over the SQLite C API. Every failure becomes colorlab::Error: io_error for
// disk-level trouble (full, read-only, I/O), conflict for constraint violations, internal otherwise.
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "colorlab/core/thread_account.hpp"

struct sqlite3;
struct sqlite3_stmt;

namespace colorlab::store {

class Statement;

// A transaction that holds the write lock this long is logged: every other writer, the io thread among them, waited
// that long, and it is the API's target for an answer (issue 27).
inline constexpr std::chrono::milliseconds kLongWriteLockHold{50};

// What a writer connection's WAL hook (wal_policy.cpp) keeps. SQLite calls the hook once a commit is durable and
// its write lock released; a checkpoint it then runs happens inside the same COMMIT call, on the same thread, with
// other writers free to go on. On the heap, so that a moved Database keeps the address the hook was given.
struct WalHookState {
  std::uint64_t commits = 0;                            // commits seen by the hook on this connection
  std::chrono::steady_clock::time_point last_commit{};  // when the last of them released the write lock
  // Set by a Transaction at BEGIN. A commit that releases the lock kLongWriteLockHold or more after it takes the
  // thread's account at the release, before a checkpoint in the same call, so that the logged hold is split up to
  // the release and no further (account_at_release, cleared by the Transaction before its COMMIT).
  std::chrono::steady_clock::time_point write_lock_since{};
  ThreadAccount account_at_release;
  std::uint64_t checkpoints = 0;          // checkpoints this connection ran (SQLITE_OK)
  std::uint64_t checkpoint_failures = 0;  // in a row (a full disk): logged at the first and every 100th
  // Set: this connection never checkpoints itself; past the threshold it calls this instead, which must not
  // block (colorlabd's io thread hands its checkpoints to the step committer's thread).
  std::function<void()> checkpoint_elsewhere;
};

class Database {
 public:
  Database() = default;
  Database(const std::string& path, bool read_only);
  ~Database();
  Database(Database&& o) noexcept;
  Database& operator=(Database&& o) noexcept;
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  void exec(std::string_view sql);
  Statement prepare(std::string_view sql);
  std::int64_t last_insert_rowid() const;
  int changes() const;
  sqlite3* handle() const { return db_; }
  [[noreturn]] void fail(int rc, std::string_view what) const;

  // The WAL hook's state, once apply_wal_policy() has installed it (nullptr before, and on read-only connections).
  WalHookState* wal_hook_state() const { return wal_hook_.get(); }
  void keep_wal_hook_state(std::unique_ptr<WalHookState> state) { wal_hook_ = std::move(state); }

 private:
  sqlite3* db_ = nullptr;
  std::string path_;
  std::unique_ptr<WalHookState> wal_hook_;
};

class Statement {
 public:
  Statement(const Database& db, sqlite3_stmt* stmt) : db_(&db), stmt_(stmt) {}
  ~Statement();
  Statement(Statement&& o) noexcept : db_(o.db_), stmt_(o.stmt_) { o.stmt_ = nullptr; }
  Statement(const Statement&) = delete;

  Statement& bind(int index, std::int64_t v);
  Statement& bind(int index, double v);
  Statement& bind(int index, std::string_view v);
  Statement& bind_null(int index);
  Statement& bind(int index, const std::optional<std::string>& v) {
    return v ? bind(index, std::string_view(*v)) : bind_null(index);
  }

  // True while a row is available.
  bool step();
  void run() {
    while (step()) {
    }
  }
  // Ready to run again with new bindings (one prepared statement for many rows).
  void reset();

  std::int64_t int64(int col) const;
  double real(int col) const;
  std::string text(int col) const;
  bool is_null(int col) const;

 private:
  const Database* db_;
  sqlite3_stmt* stmt_;
};

// BEGIN DEFERRED ... COMMIT around reads, so they all come from one snapshot of the database until it is dropped:
// what another connection commits meanwhile is not seen (a reader beside colorlabd's writer: the shipping agent, the
// bench's own shipping lag; an event stream's snapshot and its seq, through Store::read_snapshot). Inside a
// transaction already (a caller's), it joins it: that transaction's snapshot is the one read. Ending a read-only
// transaction cannot lose anything, so a failed COMMIT in the destructor is logged, not thrown.
class ReadTransaction {
 public:
  explicit ReadTransaction(Database& db);
  ~ReadTransaction();
  ReadTransaction(const ReadTransaction&) = delete;
  ReadTransaction& operator=(const ReadTransaction&) = delete;

 private:
  Database& db_;
  bool open_ = false;
};

// BEGIN IMMEDIATE ... COMMIT, rolled back unless commit() was called.
class Transaction {
 public:
  explicit Transaction(Database& db);
  ~Transaction();
  void commit();

 private:
  Database& db_;
  bool done_ = false;
  // From BEGIN IMMEDIATE's return to the commit's release of the lock (the WAL hook's time: a checkpoint SQLite
  // runs after it, in the same call, holds up this thread only): a long hold is logged, since every other writer —
  // the io thread among them — waited that long (busy_retry.hpp).
  std::chrono::steady_clock::time_point holding_since_;
  // The holding thread's own account at BEGIN: a long hold is split into its CPU, its wait for a CPU and the
  // rest (blocked: the WAL's fsync, a lock), which says whether the disk or the scheduler made it long.
  ThreadAccount account_at_begin_;
};

}  // namespace colorlab::store
