// How late a writer gets SQLite's write lock after another connection releases it: SQLite's own busy handler
// (busy_timeout, its sleeps growing to 100 ms) beside colorlab's (colorlab/store/busy_retry.hpp, a retry every
// 250 µs), in one run, interleaved. The holder keeps the lock 2, 20 or 80 ms, as a step's commit, a commit behind a
// slow disk and a checkpoint might. The time reported is the lateness only: from the holder's COMMIT returning to
// the waiter's BEGIN IMMEDIATE returning (docs/PERFORMANCE.md, "The writers' wait for the lock").
#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <future>
#include <string>
#include <thread>
#include <vector>

#include "colorlab/store/busy_retry.hpp"
#include "colorlab/store/store.hpp"
#include "colorlab/testing/temp_dir.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using colorlab::store::Database;
using colorlab::store::Transaction;

enum Handler {
  kSqliteBusyTimeout = 0,
  kRetryPromptly = 1
};

void BM_WriterWaitsForTheLock(benchmark::State& state) {
  const auto handler = static_cast<Handler>(state.range(0));
  const auto hold = std::chrono::milliseconds(state.range(1));
  colorlab::testing::TempDir dir;
  const auto path = (dir / "colorlab.db").string();
  { colorlab::store::Store made(path); }
  Database holder(path, false);
  Database waiter(path, false);
  holder.exec("CREATE TABLE written (who TEXT NOT NULL)");
  if (handler == kSqliteBusyTimeout) {
    waiter.exec("PRAGMA busy_timeout = " + std::to_string(colorlab::store::kBusyTimeout.count()));
  } else {
    colorlab::store::retry_promptly_when_busy(waiter, colorlab::store::kBusyTimeout);
  }
  for (auto _ : state) {
    std::promise<void> held;
    Clock::time_point released;
    std::thread holding([&] {
      Transaction tx(holder);
      holder.exec("INSERT INTO written VALUES ('holder')");
      held.set_value();
      std::this_thread::sleep_for(hold);
      tx.commit();
      released = Clock::now();
    });
    held.get_future().wait();
    Clock::time_point got;
    {
      Transaction tx(waiter);
      got = Clock::now();
      waiter.exec("INSERT INTO written VALUES ('waiter')");
      tx.commit();
    }
    holding.join();
    state.SetIterationTime(std::max(0.0, std::chrono::duration<double>(got - released).count()));
  }
}
BENCHMARK(BM_WriterWaitsForTheLock)
    ->ArgNames({"colorlab", "hold_ms"})
    ->ArgsProduct({{kSqliteBusyTimeout, kRetryPromptly}, {2, 20, 80}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(20);

}  // namespace

// Interleaved repetitions by default, so both handlers are measured under the same load; flags override.
int main(int argc, char** argv) {
  std::vector<char*> args(argv, argv + argc);
  std::string reps = "--benchmark_repetitions=5", interleave = "--benchmark_enable_random_interleaving=true",
              aggregates = "--benchmark_report_aggregates_only=true";
  args.insert(args.begin() + 1, {reps.data(), interleave.data(), aggregates.data()});
  int n = static_cast<int>(args.size());
  benchmark::Initialize(&n, args.data());
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
