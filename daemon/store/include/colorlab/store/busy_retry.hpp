#pragma once
// How a writer waits for SQLite's write lock while another connection holds it. colorlabd has two writers of its own
// (the io thread's and the step committer's, store.hpp's SecondWriter), and a backup or an operator's sqlite3 may
// hold the lock too.
//
// SQLite's own handler (busy_timeout) sleeps 1, 2, 5, 10, 15, 20, 25, 25, 25, 50, 50, 100 ms between tries, so a
// writer that finds the lock held for 20 ms gets it at 33 ms, and one that finds it held for 80 ms only at 103 ms.
// On the io thread that lateness becomes every queued route's (docs/PERFORMANCE.md, "The writers' wait for the
// lock"). This handler tries again every kBusyRetryInterval until the timeout, so the wait ends within about one
// interval of the lock's release; the polling costs a wake-up per interval, and only while waiting.
#include <chrono>

#include "colorlab/store/sqlite.hpp"

namespace colorlab::store {

inline constexpr std::chrono::microseconds kBusyRetryInterval{250};
inline constexpr std::chrono::milliseconds kBusyTimeout{5000};  // the store's connections' longest wait for one lock

// Installs the handler on this connection, replacing busy_timeout's. After `timeout` of waiting for one lock the
// statement fails with SQLITE_BUSY (Database::fail: an io_error saying the database is locked).
void retry_promptly_when_busy(Database& db, std::chrono::milliseconds timeout);
// No waiting at all: a held lock fails the statement at once (a checkpoint that must not wait for readers).
void never_wait_when_busy(Database& db);

}  // namespace colorlab::store
