// The crash-loop guard's policy (crash_loop.hpp): when it trips, the back-off's growth and bound, when it
// gives up, and a back-off that survives a restart without being stretched by a wall clock stepped back.
#include <gtest/gtest.h>

#include "colorlab/core/ids.hpp"
#include "colorlab/daemon/crash_loop.hpp"

using namespace colorlab::daemon;
using Kind = CrashLoopVerdict::Kind;

TEST(CrashLoopGuard, BackOffDoublesUpToItsBound) {
  CrashLoopPolicy p{3, 60, 1800, 8};
  EXPECT_EQ(p.backoff(1), 60);
  EXPECT_EQ(p.backoff(2), 120);
  EXPECT_EQ(p.backoff(3), 240);
  EXPECT_EQ(p.backoff(5), 960);
  EXPECT_EQ(p.backoff(6), 1800);  // 1920 capped
  EXPECT_EQ(p.backoff(8), 1800);
  EXPECT_EQ(p.backoff(1000), 1800);
}

TEST(CrashLoopGuard, TripsAfterTheAttemptsThenSuspendsForEachRetryThenGivesUp) {
  CrashLoopPolicy p{3, 60, 1800, 2};
  for (int attempts = 0; attempts <= 3; ++attempts) EXPECT_EQ(judge_crash_loop(p, attempts).kind, Kind::resume);
  auto first = judge_crash_loop(p, 4);
  EXPECT_EQ(first.kind, Kind::suspend);
  EXPECT_EQ(first.round, 1);
  EXPECT_EQ(first.backoff_s, 60);
  auto second = judge_crash_loop(p, 5);
  EXPECT_EQ(second.kind, Kind::suspend);
  EXPECT_EQ(second.round, 2);
  EXPECT_EQ(second.backoff_s, 120);
  EXPECT_EQ(judge_crash_loop(p, 6).kind, Kind::give_up);
  // No retries at all: the guard ends the run as soon as it trips.
  EXPECT_EQ(judge_crash_loop(CrashLoopPolicy{1, 60, 60, 0}, 2).kind, Kind::give_up);
}

TEST(CrashLoopGuard, ItsProblemIsACrashLoopNotAnInstrumentError) {
  auto problem = crash_loop_problem("colorlabd stopped 4 times", "look at the log");
  EXPECT_EQ(problem["code"], "crash-loop");
  EXPECT_EQ(problem["title"], "Crash loop");
  EXPECT_EQ(problem["status"], 503);
  EXPECT_EQ(problem["hint"], "look at the log");
  EXPECT_TRUE(is_crash_loop({{"category", "crash-loop"}}));
  EXPECT_FALSE(is_crash_loop({{"category", "storage"}}));
  EXPECT_FALSE(is_crash_loop(nullptr));
}

TEST(CrashLoopGuard, WhatIsLeftOfABackOffIsBoundedByIt) {
  auto now = std::chrono::system_clock::now();
  const auto at = [&](double s) {
    return colorlab::iso8601_utc(now + std::chrono::duration_cast<std::chrono::system_clock::duration>(
                                           std::chrono::duration<double>(s)));
  };
  EXPECT_NEAR(seconds_until(at(30), 60, now), 30, 0.01);
  EXPECT_EQ(seconds_until(at(-5), 60, now), 0);     // over while the daemon was down
  EXPECT_EQ(seconds_until(at(7200), 60, now), 60);  // the clock was stepped back: never longer than the back-off
  EXPECT_EQ(seconds_until("not a time", 60, now), 60);
}

TEST(CrashLoopGuard, StartsWithinAWindowCountTheRestartsAndTheRetriesThatFit) {
  // 0, then restarts at 5, 10 (max_resume_attempts 1 + the trip), then retries 5 + 10 and 5 + 20 later.
  CrashLoopPolicy p{1, 10, 20, 2};
  EXPECT_EQ(max_starts_within(p, 1, 5), 1);
  EXPECT_EQ(max_starts_within(p, 11, 5), 3);  // 0, 5, 10
  EXPECT_EQ(max_starts_within(p, 26, 5), 4);  // 0, 5, 10, 25
  // The next run's crash loop follows at once: 50 (the start that gives up) shares a window with 55 and 60,
  // its restarts, and the 25 before it.
  EXPECT_EQ(max_starts_within(p, 16, 5), 3);
  EXPECT_EQ(max_starts_within(p, 51, 5), 5);  // e.g. 10, 25, 50, 55, 60
}
