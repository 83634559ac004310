#include "colorlab/store/busy_retry.hpp"

#include <sqlite3.h>

#include <cstdint>
#include <thread>

namespace colorlab::store {

namespace {

// SQLite passes the number of earlier calls for the same lock; the first call starts that lock's clock. The
// timeout travels in the pointer itself, so nothing has to outlive the connection.
int retry_until_timeout(void* timeout_ms, int earlier_calls) {
  using Clock = std::chrono::steady_clock;
  thread_local Clock::time_point first_refusal;
  const auto now = Clock::now();
  if (earlier_calls == 0) first_refusal = now;
  if (now - first_refusal >= std::chrono::milliseconds(reinterpret_cast<std::intptr_t>(timeout_ms))) return 0;
  std::this_thread::sleep_for(kBusyRetryInterval);
  return 1;
}

}  // namespace

void retry_promptly_when_busy(Database& db, std::chrono::milliseconds timeout) {
  sqlite3_busy_handler(db.handle(), retry_until_timeout,
                       reinterpret_cast<void*>(static_cast<std::intptr_t>(timeout.count())));
}

void never_wait_when_busy(Database& db) { sqlite3_busy_handler(db.handle(), nullptr, nullptr); }

}  // namespace colorlab::store
