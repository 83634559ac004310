#include "colorlab/core/thread_account.hpp"

#include <algorithm>
#include <cstdio>

namespace colorlab {

namespace {

std::string ms_text(std::chrono::nanoseconds d) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", static_cast<double>(d.count()) / 1e6);
  return buf;
}

}  // namespace

ThreadAccount this_thread_account() noexcept {
  ThreadAccount a;
  if (FILE* f = std::fopen("/proc/thread-self/schedstat", "r")) {
    long long on_cpu_ns = 0, waiting_ns = 0;
    a.known = std::fscanf(f, "%lld %lld", &on_cpu_ns, &waiting_ns) == 2;
    std::fclose(f);
    a.on_cpu = std::chrono::nanoseconds(on_cpu_ns);
    a.waiting_for_cpu = std::chrono::nanoseconds(waiting_ns);
  }
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
