#pragma once
// How long this thread has waited on the store's writer, for an API answer's Server-Timing `store` part (issue 27).
#include <cstdint>

namespace colorlab::store {

// The time this thread has spent, since it started, in a Transaction's BEGIN IMMEDIATE (waiting for SQLite's write
// lock: another connection's transaction, such as the step committer's) and COMMIT (the fsync of synchronous=FULL).
// What one handler waited on the store is the difference across it.
std::int64_t writer_wait_us_this_thread();

}  // namespace colorlab::store
