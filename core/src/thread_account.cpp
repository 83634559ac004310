#include "colorlab/core/thread_account.hpp"

#include <fcntl.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>

namespace colorlab {

namespace {

std::string ms_text(std::chrono::nanoseconds d) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", static_cast<double>(d.count()) / 1e6);
  return buf;
}

// Opened by the thread that reads it: /proc/thread-self names that thread for as long as the descriptor lives.
class OwnSchedstat {
 public:
  OwnSchedstat() = default;
  ~OwnSchedstat() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }
  OwnSchedstat(const OwnSchedstat&) = delete;
  OwnSchedstat& operator=(const OwnSchedstat&) = delete;

  // The second field, nanoseconds runnable but not running; -1 when unreadable. An open that failed (descriptors
  // exhausted for a moment) is tried again at the next reading, so a long-lived thread does not lose its account.
  long long waiting_ns() {
    if (fd_ < 0) fd_ = ::open("/proc/thread-self/schedstat", O_RDONLY | O_CLOEXEC);
    if (fd_ < 0) return -1;
    char text[96];
    const ssize_t n = ::pread(fd_, text, sizeof text - 1, 0);
    if (n <= 0) return -1;
    text[n] = '\0';
    char* end = nullptr;
    std::strtoll(text, &end, 10);  // run time: taken from the thread's CPU clock instead
    if (end == text) return -1;
    char* after = nullptr;
    const long long waiting = std::strtoll(end, &after, 10);
    return after == end ? -1 : waiting;
  }

 private:
  int fd_ = -1;
};

}  // namespace

std::chrono::nanoseconds this_thread_cpu_time() noexcept {
  timespec ts{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return std::chrono::seconds(ts.tv_sec) + std::chrono::nanoseconds(ts.tv_nsec);
}

ThreadAccount this_thread_account() noexcept {
  thread_local OwnSchedstat schedstat;
  ThreadAccount a;
  const long long waiting = schedstat.waiting_ns();
  if (waiting < 0) return a;
  a.known = true;
  a.on_cpu = this_thread_cpu_time();
  a.waiting_for_cpu = std::chrono::nanoseconds(waiting);
  return a;
}

std::string split_of_interval(std::chrono::nanoseconds wall, const ThreadAccount& before, const ThreadAccount& after) {
  if (!before.known || !after.known) return {};
  const auto cpu = after.on_cpu - before.on_cpu;
  const auto queued = after.waiting_for_cpu - before.waiting_for_cpu;
  const auto blocked = std::max(std::chrono::nanoseconds(0), wall - cpu - queued);
  return "of its " + ms_text(wall) + " ms: on a CPU " + ms_text(cpu) + ", waiting for a CPU " + ms_text(queued) +
         ", blocked " + ms_text(blocked);
}

}  // namespace colorlab
