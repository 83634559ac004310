// A writer finding SQLite's write lock held (colorlab/store/busy_retry.hpp): it waits and writes once the lock is
// released, and gives up with a typed error after its timeout. How soon after the release it gets the lock, beside
// SQLite's own handler, is measured in bench/daemon (bench_daemon_writer_wait, BM_WriterWaitsForTheLock).
#include <future>
#include <thread>

#include <gtest/gtest.h>

#include "colorlab/core/error.hpp"
#include "colorlab/store/busy_retry.hpp"
#include "colorlab/store/store.hpp"
#include "colorlab/testing/temp_dir.hpp"

using colorlab::Error;
using colorlab::ErrorClass;
using colorlab::store::Database;
using colorlab::store::Transaction;
using colorlab::testing::TempDir;
using namespace std::chrono_literals;

namespace {

// A database in WAL mode as colorlabd keeps it, with a table for the two writers.
std::string wal_database(const TempDir& dir) {
  const auto path = (dir / "colorlab.db").string();
  { colorlab::store::Store made(path); }
  Database db(path, false);
  db.exec("CREATE TABLE IF NOT EXISTS written (who TEXT NOT NULL)");
  return path;
}

int rows(const std::string& path) {
  Database db(path, true);
  auto st = db.prepare("SELECT count(*) FROM written");
  st.step();
  return static_cast<int>(st.int64(0));
}

// Holds the write lock on a thread of its own until `release` is set; `held` is set once it has it.
std::thread hold_the_lock(const std::string& path, std::promise<void>& held, std::shared_future<void> release) {
  return std::thread([&path, &held, release] {
    Database db(path, false);
    Transaction tx(db);
    db.exec("INSERT INTO written VALUES ('holder')");
    held.set_value();
    release.wait();
    tx.commit();
  });
}

}  // namespace

TEST(BusyRetry, AWriterWaitsForTheHeldLockAndWritesOnceItIsReleased) {
  TempDir dir;
  const auto path = wal_database(dir);
  std::promise<void> held, release;
  auto holder = hold_the_lock(path, held, release.get_future().share());
  held.get_future().wait();

  Database waiter(path, false);
  colorlab::store::retry_promptly_when_busy(waiter, 5000ms);
  std::thread releaser([&] {
    std::this_thread::sleep_for(60ms);  // many retry intervals: the waiter is refused many times first
    release.set_value();
  });
  {
    Transaction tx(waiter);
    waiter.exec("INSERT INTO written VALUES ('waiter')");
    tx.commit();
  }
  releaser.join();
  holder.join();
  EXPECT_EQ(rows(path), 2) << "both writers' rows are committed";
}

TEST(BusyRetry, AWriterGivesUpWithATypedErrorAfterItsTimeoutAndWritesNothing) {
  TempDir dir;
  const auto path = wal_database(dir);
  std::promise<void> held, release;
  auto holder = hold_the_lock(path, held, release.get_future().share());
  held.get_future().wait();

  Database waiter(path, false);
  colorlab::store::retry_promptly_when_busy(waiter, 50ms);
  try {
    Transaction tx(waiter);
    ADD_FAILURE() << "the lock was taken while another connection held it";
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::io_error);
    EXPECT_NE(std::string(e.what()).find("is locked"), std::string::npos) << e.what();
  }
  release.set_value();
  holder.join();
  EXPECT_EQ(rows(path), 1) << "only the holder's row";
}

TEST(BusyRetry, WithoutWaitingAHeldLockIsRefusedAtOnce) {
  TempDir dir;
  const auto path = wal_database(dir);
  std::promise<void> held, release;
  auto holder = hold_the_lock(path, held, release.get_future().share());
  held.get_future().wait();

  Database waiter(path, false);
  colorlab::store::retry_promptly_when_busy(waiter, 5000ms);
  colorlab::store::never_wait_when_busy(waiter);
  EXPECT_THROW(Transaction tx(waiter), Error);
  release.set_value();
  holder.join();
}
