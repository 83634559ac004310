// A transaction that holds SQLite's write lock long is logged with the holding thread's own account of that time
// (colorlab/core/thread_account.hpp): on a CPU, waiting for one, or blocked. The io thread's late ticks are split
// the same way. Bounds here are the kernel's own bookkeeping — a sleeping thread is neither on a CPU nor
// runnable — never how fast anything ran.
#include <chrono>
#include <regex>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "colorlab/core/thread_account.hpp"
#include "colorlab/store/sqlite.hpp"
#include "colorlab/store/wal_policy.hpp"
#include "colorlab/testing/temp_dir.hpp"

using namespace std::chrono_literals;

namespace {

void spin_on_cpu(std::chrono::nanoseconds how_long) {
  const auto until = colorlab::this_thread_cpu_time() + how_long;
  volatile unsigned sink = 0;
  while (colorlab::this_thread_cpu_time() < until) sink = sink + 1;
}

std::string long_hold_line(const std::string& log) {
  std::smatch line;
  if (!std::regex_search(log, line, std::regex("a transaction held the write lock [0-9]+ ms \\([^\\n]*"))) return {};
  return line[0];
}

double field_ms(const std::string& line, const std::string& name) {
  std::smatch m;
  if (!std::regex_search(line, m, std::regex(name + " ([0-9.]+)"))) return -1;
  return std::stod(m[1]);
}

}  // namespace

TEST(ThreadAccount, TimeSpinningIsOnACpuAndTimeAsleepIsNeither) {
  const auto start = colorlab::this_thread_account();
  if (!start.known) GTEST_SKIP() << "this kernel keeps no /proc/thread-self/schedstat";
  spin_on_cpu(30ms);
  const auto spun = colorlab::this_thread_account();
  // The same clock as CLOCK_THREAD_CPUTIME_ID (the scheduler's sum of the thread's run time).
  EXPECT_GE(spun.on_cpu - start.on_cpu, 30ms);
  std::this_thread::sleep_for(40ms);
  const auto slept = colorlab::this_thread_account();
  EXPECT_LT(slept.on_cpu - spun.on_cpu, 40ms);
  const auto split = colorlab::split_of_interval(40ms, spun, slept);
  EXPECT_NE(split.find("on a CPU"), std::string::npos) << split;
  EXPECT_NE(split.find("waiting for a CPU"), std::string::npos) << split;
  EXPECT_TRUE(colorlab::split_of_interval(40ms, colorlab::ThreadAccount{}, slept).empty());
}

TEST(WriteLockHold, ALongHoldIsLoggedWithWhatTheHoldingThreadDidMeanwhile) {
  if (!colorlab::this_thread_account().known) GTEST_SKIP() << "this kernel keeps no /proc/thread-self/schedstat";
  colorlab::testing::TempDir dir;
  colorlab::store::Database db((dir / "hold.db").string(), false);
  db.exec("PRAGMA journal_mode = WAL");
  db.exec("CREATE TABLE t (x INTEGER)");
  testing::internal::CaptureStderr();
  {
    colorlab::store::Transaction tx(db);
    db.exec("INSERT INTO t VALUES (1)");
    std::this_thread::sleep_for(80ms);  // as a thread held by a disk or a lock would be
    tx.commit();
  }
  const std::string log = testing::internal::GetCapturedStderr();
  const std::string text = long_hold_line(log);
  ASSERT_FALSE(text.empty()) << log;
  EXPECT_GE(field_ms(text, "on a CPU"), 0.0) << text;
  EXPECT_GE(field_ms(text, "waiting for a CPU"), 0.0) << text;
  // Asleep is neither on a CPU nor runnable: all 80 ms of it are "blocked", however loaded the machine.
  EXPECT_GE(field_ms(text, "blocked"), 79.0) << text;
  EXPECT_LT(field_ms(text, "on a CPU"), 80.0) << text;
}

TEST(WriteLockHold, TheSplitEndsAtTheReleaseNotAfterACheckpointInTheSameCall) {
  if (!colorlab::this_thread_account().known) GTEST_SKIP() << "this kernel keeps no /proc/thread-self/schedstat";
  colorlab::testing::TempDir dir;
  colorlab::store::Database db((dir / "hold.db").string(), false);
  db.exec("PRAGMA journal_mode = WAL");
  db.exec("CREATE TABLE t (x BLOB)");
  colorlab::store::apply_wal_policy(db);
  // What SQLite's hook runs after the release when the WAL crosses its threshold: here 100 ms on a CPU, in the same
  // COMMIT call, after the lock is free.
  colorlab::store::hand_checkpoints_elsewhere(db, [] { spin_on_cpu(100ms); });
  testing::internal::CaptureStderr();
  {
    colorlab::store::Transaction tx(db);
    // Past the hook's threshold in one commit: 1000 pages of 4 KiB.
    db.exec("INSERT INTO t VALUES (zeroblob(" + std::to_string(colorlab::store::kWalAutocheckpointPages * 4096 + 65536) + "))");
    std::this_thread::sleep_for(80ms);
    tx.commit();
  }
  const std::string log = testing::internal::GetCapturedStderr();
  const std::string text = long_hold_line(log);
  ASSERT_FALSE(text.empty()) << log;
  EXPECT_NE(text.find("from BEGIN to the release"), std::string::npos) << text;
  // The 100 ms after the release are not in it: the span is the hold's own, and most of it asleep.
  std::smatch held;
  ASSERT_TRUE(std::regex_search(text, held, std::regex("write lock ([0-9]+) ms"))) << text;
  EXPECT_NEAR(field_ms(text, "of its"), std::stod(held[1]), 0.6) << text;
  EXPECT_LT(field_ms(text, "on a CPU"), 80.0) << text;
  EXPECT_GE(field_ms(text, "blocked"), 79.0) << text;
}
