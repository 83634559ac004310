#include "colorlab/sim/capture_scratch.hpp"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <fstream>
#include <string>

namespace colorlab::sim {

namespace {

constexpr std::string_view kPrefix = "colorlab-sim-";
constexpr std::string_view kSuffix = "-dslr";

// The pid in "colorlab-sim-<pid>-dslr", or 0 when the name is not one of ours.
pid_t pid_of(const std::string& name) {
  if (name.size() <= kPrefix.size() + kSuffix.size()) return 0;
  if (name.compare(0, kPrefix.size(), kPrefix) != 0) return 0;
  if (name.compare(name.size() - kSuffix.size(), kSuffix.size(), kSuffix) != 0) return 0;
  const char* first = name.data() + kPrefix.size();
  const char* last = name.data() + name.size() - kSuffix.size();
  long value = 0;
  auto [end, ec] = std::from_chars(first, last, value);
  if (ec != std::errc() || end != last || value <= 0) return 0;
  return static_cast<pid_t>(value);
}

// The pid in "colorlab-sim-<pid>.sock" or "colorlab-sim-<pid>-<name>.sock", or 0.
pid_t socket_pid_of(const std::string& name) {
  constexpr std::string_view kSock = ".sock";
  if (name.size() <= kPrefix.size() + kSock.size()) return 0;
  if (name.compare(0, kPrefix.size(), kPrefix) != 0) return 0;
  if (name.compare(name.size() - kSock.size(), kSock.size(), kSock) != 0) return 0;
  const char* first = name.data() + kPrefix.size();
  const char* last = name.data() + name.size() - kSock.size();
  long value = 0;
  auto [end, ec] = std::from_chars(first, last, value);
  if (ec != std::errc() || value <= 0 || (end != last && *end != '-')) return 0;
  return static_cast<pid_t>(value);
}

}  // namespace

std::vector<std::filesystem::path> reclaim_dead_sockets(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> removed;
  std::error_code ec;
  std::filesystem::directory_iterator it(dir, ec), end;
  if (ec) return removed;
  const pid_t self = ::getpid();
  for (; it != end; it.increment(ec)) {
    if (ec) break;
    const pid_t pid = socket_pid_of(it->path().filename().string());
    if (pid == 0 || pid == self) continue;
    std::error_code type_ec;
    if (!it->is_socket(type_ec) || !process_is_gone(pid)) continue;
    std::error_code rm_ec;
    if (std::filesystem::remove(it->path(), rm_ec)) removed.push_back(it->path());
  }
  return removed;
}

std::filesystem::path default_capture_dir(const std::filesystem::path& root, pid_t pid) {
  return root / (std::string(kPrefix) + std::to_string(pid) + std::string(kSuffix));
}

bool process_is_gone(pid_t pid) {
  if (::kill(pid, 0) != 0) return errno == ESRCH;  // EPERM: another user's live process
  // kill(0) succeeds on a zombie; its state letter follows the last ')' of /proc/<pid>/stat.
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(stat)), std::istreambuf_iterator<char>());
  auto paren = text.rfind(')');
  if (paren == std::string::npos || paren + 2 >= text.size()) return false;
  const char state = text[paren + 2];
  return state == 'Z' || state == 'X';
}

std::vector<std::filesystem::path> reclaim_dead_capture_dirs(const std::filesystem::path& root) {
  std::vector<std::filesystem::path> removed;
  std::error_code ec;
  std::filesystem::directory_iterator it(root, ec), end;
  if (ec) return removed;
  const pid_t self = ::getpid();
  for (; it != end; it.increment(ec)) {
    if (ec) break;
    const pid_t pid = pid_of(it->path().filename().string());
    if (pid == 0 || pid == self) continue;
    std::error_code type_ec;
    if (!it->is_directory(type_ec) || it->is_symlink(type_ec)) continue;
    if (!process_is_gone(pid)) continue;
    std::error_code rm_ec;
    std::filesystem::remove_all(it->path(), rm_ec);
    if (!rm_ec) removed.push_back(it->path());
  }
  return removed;
}

}  // namespace colorlab::sim
