#pragma once
// Plays systemd's side of sd_notify: a datagram socket a child started with NOTIFY_SOCKET=path
// writes READY=1, WATCHDOG=1, STATUS=… to.
#include <chrono>
#include <filesystem>
#include <string>

namespace colorlab::testing {

class NotifySocket {
 public:
  explicit NotifySocket(const std::filesystem::path& path);
  ~NotifySocket();
  NotifySocket(const NotifySocket&) = delete;
  NotifySocket& operator=(const NotifySocket&) = delete;

  // The next datagram, or "" after `timeout`.
  std::string receive(std::chrono::milliseconds timeout);
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  int fd_ = -1;
};

}  // namespace colorlab::testing
