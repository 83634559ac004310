#include "colorlab/core/thread_priority.hpp"

#include <pthread.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include "colorlab/core/error.hpp"
#include "colorlab/core/log.hpp"

namespace colorlab::core {

namespace {
std::atomic<int> g_heavy_nice{0};

long this_tid() { return static_cast<long>(::syscall(SYS_gettid)); }
}  // namespace

void set_heavy_thread_nice(int steps) { g_heavy_nice.store(std::clamp(steps, 0, 19)); }

int heavy_thread_nice() { return g_heavy_nice.load(); }

void lower_this_thread(int steps, std::string_view who) {
  if (steps <= 0) return;
  const auto tid = static_cast<id_t>(this_tid());
  // Counted from the process's own nice (its main thread's), not this thread's: a heavy thread started by another
  // heavy thread (a camera's decode thread rebuilt on its device thread) inherits the lowered value, and lowering
  // it again would stack the steps down to 19.
  errno = 0;
  const int base = ::getpriority(PRIO_PROCESS, static_cast<id_t>(::getpid()));
  const int base_errno = errno;
  errno = 0;
  const int now = ::getpriority(PRIO_PROCESS, tid);
  if ((base == -1 && base_errno != 0) || (now == -1 && errno != 0)) {
    log::warning("priority", std::string(who) + ": cannot read its nice value: " + std::strerror(errno ? errno : base_errno));
    return;
  }
  const int target = std::min(19, base + steps);
  if (now >= target) return;
  if (::setpriority(PRIO_PROCESS, tid, target) != 0) {
    log::warning("priority", std::string(who) + ": cannot lower its CPU priority: " + std::strerror(errno));
  }
}

void become_heavy_thread(std::string_view name) {
  const std::string n(name.substr(0, 15));
  pthread_setname_np(pthread_self(), n.c_str());
  lower_this_thread(heavy_thread_nice(), n);
}

int thread_nice(long tid) {
  if (tid == 0) tid = this_tid();
  return nice_in_stat("/proc/self/task/" + std::to_string(tid) + "/stat");
}

int nice_in_stat(const std::filesystem::path& stat_file) {
  const std::string path = stat_file.string();
  std::ifstream in(path);
  if (!in) throw Error(ErrorClass::io_error, "cannot read " + path, "the thread or process may have ended");
  std::string stat((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // The command name (field 2) may hold spaces and parentheses: fields are counted after its last ')'.
  const auto close = stat.rfind(')');
  if (close == std::string::npos) throw Error(ErrorClass::bad_data, path + " is not a thread's stat line: " + stat);
  std::istringstream fields(stat.substr(close + 1));
  std::string field;
  // After ')': state is field 3, nice is field 19, so 17 fields in.
  for (int i = 3; i <= 19; ++i) {
    if (!(fields >> field)) throw Error(ErrorClass::bad_data, path + " has fewer than 19 fields: " + stat);
  }
  try {
    return std::stoi(field);
  } catch (const std::exception&) {
    throw Error(ErrorClass::bad_data, path + ": its nice field is not a number: " + field);
  }
}

}  // namespace colorlab::core
