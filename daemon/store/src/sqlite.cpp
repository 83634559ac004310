#include "colorlab/store/sqlite.hpp"

#include <pthread.h>
#include <sqlite3.h>

#include <chrono>
#include <cmath>

#include "colorlab/core/error.hpp"
#include "colorlab/core/log.hpp"
#include "colorlab/store/writer_wait.hpp"

namespace colorlab::store {

Database::Database(const std::string& path, bool read_only) : path_(path) {
  int flags = read_only ? SQLITE_OPEN_READONLY : (SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
  flags |= SQLITE_OPEN_NOMUTEX;
  int rc = sqlite3_open_v2(path.c_str(), &db_, flags, nullptr);
  if (rc != SQLITE_OK) {
    std::string msg = db_ ? sqlite3_errmsg(db_) : sqlite3_errstr(rc);
    sqlite3_close_v2(db_);
    db_ = nullptr;
    throw Error(ErrorClass::io_error, "cannot open database " + path + ": " + msg,
                "check that the state directory exists, is writable and is on a local disk");
  }
  sqlite3_extended_result_codes(db_, 1);
}

Database::~Database() {
  if (db_) sqlite3_close_v2(db_);
}

Database::Database(Database&& o) noexcept : db_(o.db_), path_(std::move(o.path_)), wal_hook_(std::move(o.wal_hook_)) {
  o.db_ = nullptr;
}

Database& Database::operator=(Database&& o) noexcept {
  if (this != &o) {
    if (db_) sqlite3_close_v2(db_);
    db_ = o.db_;
    path_ = std::move(o.path_);
    wal_hook_ = std::move(o.wal_hook_);  // the hook's state goes with the connection it was installed on
    o.db_ = nullptr;
  }
  return *this;
}

void Database::fail(int rc, std::string_view what) const {
  std::string msg = std::string(what) + ": " + (db_ ? sqlite3_errmsg(db_) : sqlite3_errstr(rc));
  switch (rc & 0xff) {
    case SQLITE_FULL:
      throw Error(ErrorClass::io_error, "disk full writing " + path_ + " (" + msg + ")",
                  "free space on the state directory's disk; nothing already committed was lost");
    case SQLITE_IOERR:
    case SQLITE_READONLY:
    case SQLITE_CANTOPEN:
    case SQLITE_CORRUPT:
    case SQLITE_NOTADB:
      throw Error(ErrorClass::io_error, path_ + ": " + msg, "check the disk and the database file");
    case SQLITE_BUSY:
    case SQLITE_LOCKED:
      throw Error(ErrorClass::io_error, path_ + " is locked: " + msg,
                  "another process holds the database; only colorlabd should write it");
    case SQLITE_CONSTRAINT: throw Error(ErrorClass::conflict, msg);
    default: throw Error(ErrorClass::internal, msg);
  }
}

void Database::exec(std::string_view sql) {
  char* err = nullptr;
  std::string s(sql);
  int rc = sqlite3_exec(db_, s.c_str(), nullptr, nullptr, &err);
  if (rc != SQLITE_OK) {
    std::string m = err ? err : "";
    sqlite3_free(err);
    fail(rc, m);
  }
}

Statement Database::prepare(std::string_view sql) {
  sqlite3_stmt* stmt = nullptr;
  int rc = sqlite3_prepare_v2(db_, sql.data(), static_cast<int>(sql.size()), &stmt, nullptr);
  if (rc != SQLITE_OK) fail(rc, "prepare");
  return Statement(*this, stmt);
}

std::int64_t Database::last_insert_rowid() const { return sqlite3_last_insert_rowid(db_); }
int Database::changes() const { return sqlite3_changes(db_); }

Statement::~Statement() {
  if (stmt_) sqlite3_finalize(stmt_);
}

Statement& Statement::bind(int i, std::int64_t v) {
  if (int rc = sqlite3_bind_int64(stmt_, i, v); rc != SQLITE_OK) db_->fail(rc, "bind");
  return *this;
}
Statement& Statement::bind(int i, double v) {
  if (int rc = sqlite3_bind_double(stmt_, i, v); rc != SQLITE_OK) db_->fail(rc, "bind");
  return *this;
}
Statement& Statement::bind(int i, std::string_view v) {
  if (int rc = sqlite3_bind_text(stmt_, i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT); rc != SQLITE_OK)
    db_->fail(rc, "bind");
  return *this;
}
Statement& Statement::bind_null(int i) {
  if (int rc = sqlite3_bind_null(stmt_, i); rc != SQLITE_OK) db_->fail(rc, "bind");
  return *this;
}

bool Statement::step() {
  int rc = sqlite3_step(stmt_);
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  db_->fail(rc, "step");
}

void Statement::reset() {
  sqlite3_reset(stmt_);
  sqlite3_clear_bindings(stmt_);
}

std::int64_t Statement::int64(int col) const { return sqlite3_column_int64(stmt_, col); }
double Statement::real(int col) const { return sqlite3_column_double(stmt_, col); }
std::string Statement::text(int col) const {
  auto p = sqlite3_column_text(stmt_, col);
  return p ? std::string(reinterpret_cast<const char*>(p), sqlite3_column_bytes(stmt_, col)) : std::string();
}
bool Statement::is_null(int col) const { return sqlite3_column_type(stmt_, col) == SQLITE_NULL; }

namespace {

thread_local std::int64_t writer_wait_us = 0;

// Adds its lifetime to this thread's writer wait, also when the statement throws.
class WriterWaitTimer {
 public:
  WriterWaitTimer() : start_(std::chrono::steady_clock::now()) {}
  ~WriterWaitTimer() {
    writer_wait_us +=
        std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - start_).count();
  }
  WriterWaitTimer(const WriterWaitTimer&) = delete;
  WriterWaitTimer& operator=(const WriterWaitTimer&) = delete;

 private:
  std::chrono::steady_clock::time_point start_;
};

}  // namespace

std::int64_t writer_wait_us_this_thread() { return writer_wait_us; }

ReadTransaction::ReadTransaction(Database& db) : db_(db) {
  if (sqlite3_get_autocommit(db_.handle()) == 0) return;
  db_.exec("BEGIN DEFERRED");
  open_ = true;
}

ReadTransaction::~ReadTransaction() {
  if (!open_) return;
  try {
    db_.exec("COMMIT");
  } catch (const Error& e) {
    log::warning("store", std::string("cannot end a read transaction: ") + e.what());
  }
}

Transaction::Transaction(Database& db) : db_(db) {
  WriterWaitTimer timed;
  db_.exec("BEGIN IMMEDIATE");
  holding_since_ = std::chrono::steady_clock::now();
  account_at_begin_ = this_thread_account();
  if (WalHookState* hook = db_.wal_hook_state()) hook->write_lock_since = holding_since_;
}

Transaction::~Transaction() {
  if (!done_) {
    if (WalHookState* hook = db_.wal_hook_state()) hook->write_lock_since = {};
    try {
      db_.exec("ROLLBACK");
    } catch (...) {
      // The transaction may already be rolled back by SQLite after an I/O error.
    }
  }
}

void Transaction::commit() {
  WalHookState* hook = db_.wal_hook_state();
  const std::uint64_t commits_before = hook ? hook->commits : 0;
  if (hook) hook->account_at_release = {};
  {
    WriterWaitTimer timed;
    db_.exec("COMMIT");
  }
  done_ = true;
  const bool hooked = hook && hook->commits != commits_before;
  // A COMMIT that wrote nothing never reaches the hook: BEGIN's time must not make a later autocommit "long".
  if (hook) hook->write_lock_since = {};
  const auto released = hooked ? hook->last_commit : std::chrono::steady_clock::now();
  const std::chrono::duration<double, std::milli> held = released - holding_since_;
  if (held >= kLongWriteLockHold) {
    char thread[16] = "?";
    pthread_getname_np(pthread_self(), thread, sizeof thread);
    // Up to the release where the hook took the account there. Without a hook (a connection with no WAL policy)
    // the account is now's, after whatever else the COMMIT call did, and the line says so.
    const bool at_release = hooked && hook->account_at_release.known;
    const std::string split =
        at_release ? split_of_interval(released - holding_since_, account_at_begin_, hook->account_at_release)
                   : split_of_interval(std::chrono::steady_clock::now() - holding_since_, account_at_begin_,
                                       this_thread_account());
    const std::string span = at_release ? "; from BEGIN to the release, " : "; from BEGIN to the COMMIT's end, ";
    log::warning("store", "a transaction held the write lock " + std::to_string(std::lround(held.count())) +
                              " ms (thread " + thread + (split.empty() ? "" : span + split) +
                              "); other writers waited up to that long");
  }
}

}  // namespace colorlab::store
