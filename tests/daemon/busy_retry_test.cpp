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

// Another connection holds the write lock, on a thread of its own, from SetUp until release().
class BusyRetry : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = wal_database(dir_);
    std::promise<void> held;
    holder_ = std::thread([this, &held, released = release_.get_future()] {
      Database db(path_, false);
      Transaction tx(db);
      db.exec("INSERT INTO written VALUES ('holder')");
      held.set_value();
      released.wait();
      tx.commit();
    });
    held.get_future().wait();
  }
  void TearDown() override { release(); }
  void release() {
    if (!holder_.joinable()) return;
    release_.set_value();
    holder_.join();
  }

  TempDir dir_;
  std::string path_;
  std::promise<void> release_;
  std::thread holder_;
};

}  // namespace

TEST_F(BusyRetry, AWriterWaitsForTheHeldLockAndWritesOnceItIsReleased) {
  Database waiter(path_, false);
  colorlab::store::retry_promptly_when_busy(waiter, 5000ms);
  std::thread releaser([this] {
    std::this_thread::sleep_for(60ms);  // many retry intervals: the waiter is refused many times first
    release();
  });
  {
    Transaction tx(waiter);
    waiter.exec("INSERT INTO written VALUES ('waiter')");
    tx.commit();
  }
  releaser.join();
  EXPECT_EQ(rows(path_), 2) << "both writers' rows are committed";
}

TEST_F(BusyRetry, AWriterGivesUpWithATypedErrorAfterItsTimeoutAndWritesNothing) {
  Database waiter(path_, false);
  colorlab::store::retry_promptly_when_busy(waiter, 50ms);
  try {
    Transaction tx(waiter);
    ADD_FAILURE() << "the lock was taken while another connection held it";
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::io_error);
    EXPECT_NE(std::string(e.what()).find("is locked"), std::string::npos) << e.what();
  }
  release();
  EXPECT_EQ(rows(path_), 1) << "only the holder's row";
}

TEST_F(BusyRetry, WithoutWaitingAHeldLockIsRefusedAtOnce) {
  Database waiter(path_, false);
  colorlab::store::retry_promptly_when_busy(waiter, 5000ms);
  colorlab::store::never_wait_when_busy(waiter);
  EXPECT_THROW(Transaction tx(waiter), Error);
}
