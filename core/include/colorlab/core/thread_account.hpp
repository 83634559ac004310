#pragma once
// What the calling thread has spent so far by the kernel's own account: time on a CPU (CLOCK_THREAD_CPUTIME_ID),
// and time runnable but waiting for one (Linux /proc/thread-self/schedstat). Two readings around an interval, taken
// from its wall time, leave what the thread spent blocked (a disk, a lock, a sleep).
#include <chrono>
#include <string>

namespace colorlab {

// The calling thread's CPU time so far: up to date at the call, where schedstat's own run time lags by as much as a
// scheduler tick for a thread that is on a CPU.
std::chrono::nanoseconds this_thread_cpu_time() noexcept;

struct ThreadAccount {
  std::chrono::nanoseconds on_cpu{0};
  std::chrono::nanoseconds waiting_for_cpu{0};
  bool known = false;  // no schedstat (a kernel without CONFIG_SCHED_INFO): nothing above is meaningful
};

// A few microseconds: each thread keeps its schedstat file open (close-on-exec) and reads it again with pread.
ThreadAccount this_thread_account() noexcept;

// "of its W ms: on a CPU C, waiting for a CPU Q, blocked B" for an interval of `wall` between two readings of the
// same thread; empty when either reading is unknown.
std::string split_of_interval(std::chrono::nanoseconds wall, const ThreadAccount& before, const ThreadAccount& after);

}  // namespace colorlab
