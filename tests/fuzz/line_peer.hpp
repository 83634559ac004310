#pragma once
// The far end of a simulated lab's socket device for fuzzing its driver's client side: a Unix socket
// in a private temporary directory whose one peer thread answers every connection with the current
// input's bytes, then closes its side. The driver under test reads those bytes as the device's
// answers, line by line, exactly as it reads the simulated lab's.
#include <stdlib.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>

namespace colorlab::fuzz {

class LinePeer {
 public:
  explicit LinePeer(const char* socket_name) {
    char dir[] = "/tmp/colorlab-fuzz-XXXXXX";
    if (!::mkdtemp(dir)) fail("mkdtemp");
    dir_ = dir;
    path_ = (dir_ / socket_name).string();
    listen_fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::memcpy(addr.sun_path, path_.c_str(), path_.size() + 1);
    if (listen_fd_ < 0 || ::bind(listen_fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0 ||
        ::listen(listen_fd_, 4) != 0) {
      fail("listen");
    }
    std::thread([this] { serve(); }).detach();
  }
  ~LinePeer() {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }

  const std::string& path() const { return path_; }
  // What the next connection will be answered.
  void set_answers(std::string_view bytes) {
    std::lock_guard lock(mutex_);
    answers_ = bytes;
  }

 private:
  [[noreturn]] static void fail(const char* what) {
    std::perror(what);
    std::abort();
  }

  void serve() {
    for (;;) {
      const int c = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
      if (c < 0) continue;
      std::string out;
      {
        std::lock_guard lock(mutex_);
        out = answers_;
      }
      for (std::size_t sent = 0; sent < out.size();) {
        const ssize_t n = ::send(c, out.data() + sent, out.size() - sent, MSG_NOSIGNAL);
        if (n <= 0) break;
        sent += static_cast<std::size_t>(n);
      }
      ::shutdown(c, SHUT_WR);
      char sink[4096];
      while (::recv(c, sink, sizeof sink, 0) > 0) {
      }
      ::close(c);
    }
  }

  std::filesystem::path dir_;
  std::string path_;
  int listen_fd_ = -1;
  std::mutex mutex_;
  std::string answers_;
};

}  // namespace colorlab::fuzz
