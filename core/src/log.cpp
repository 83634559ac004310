#include "colorlab/core/log.hpp"

#include <atomic>
#include <cstdio>
#include <mutex>
#include <string>

namespace colorlab::log {

namespace {
std::atomic<int> g_max_level{static_cast<int>(Level::info)};
std::mutex g_mutex;
}  // namespace

void set_level(Level max_level) { g_max_level = static_cast<int>(max_level); }

void write(Level level, std::string_view component, std::string_view message) {
  if (static_cast<int>(level) > g_max_level.load()) return;
  std::string line = "<" + std::to_string(static_cast<int>(level)) + ">" + std::string(component) + ": " +
                     std::string(message) + "\n";
  std::lock_guard lock(g_mutex);
  std::fwrite(line.data(), 1, line.size(), stderr);
}

}  // namespace colorlab::log
