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
  errno = 0;
  const int now = ::getpriority(PRIO_PROCESS, tid);
  if (now == -1 && errno != 0) {
    log::warning("priority", std::string(who) + ": cannot read its nice value: " + std::strerror(errno));
    return;
  }
  if (::setpriority(PRIO_PROCESS, tid, std::min(19, now + steps)) != 0) {
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
  return std::stoi(field);
}

}  // namespace colorlab::core
