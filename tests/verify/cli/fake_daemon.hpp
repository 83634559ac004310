#pragma once
// A stand-in for colorlabd on 127.0.0.1 for the CLI's tests: each GET path (the query ignored) answers what the test
// set, every other path a 404 problem as colorlabd answers an unknown route. One request per connection, as the
// client sends them (keep-alive off); the paths asked are kept, so a test can say which routes the CLI consulted.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace colorlab::verify::testing {

class FakeDaemon {
 public:
  struct Answer {
    int status = 200;
    std::string body;
    std::string content_type = "application/json";
  };

  FakeDaemon() {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t n = sizeof a;
    if (fd_ < 0 || ::bind(fd_, reinterpret_cast<sockaddr*>(&a), n) != 0 || ::listen(fd_, 16) != 0 ||
        ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &n) != 0)
      throw std::runtime_error("fake daemon: cannot listen on 127.0.0.1");
    port_ = ntohs(a.sin_port);
    thread_ = std::thread([this] { serve(); });
  }
  ~FakeDaemon() {
    stop_ = true;
    thread_.join();
    ::close(fd_);
  }
  FakeDaemon(const FakeDaemon&) = delete;
  FakeDaemon& operator=(const FakeDaemon&) = delete;

  std::string url() const { return "http://127.0.0.1:" + std::to_string(port_); }
  void answer(const std::string& path, Answer a) {
    std::lock_guard lock(m_);
    routes_[path] = std::move(a);
  }
  void forget(const std::string& path) {
    std::lock_guard lock(m_);
    routes_.erase(path);
  }
  std::vector<std::string> asked() {
    std::lock_guard lock(m_);
    return asked_;
  }
  void clear_asked() {
    std::lock_guard lock(m_);
    asked_.clear();
  }

 private:
  void serve() {
    while (!stop_) {
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, 50) <= 0) continue;
      const int c = ::accept(fd_, nullptr, nullptr);
      if (c < 0) continue;
      one(c);
      ::close(c);
    }
  }

  void one(int c) {
    std::string head;
    char buf[4096];
    while (head.find("\r\n\r\n") == std::string::npos) {
      pollfd p{c, POLLIN, 0};
      if (::poll(&p, 1, 5000) <= 0) return;
      const ssize_t got = ::recv(c, buf, sizeof buf, 0);
      if (got <= 0) return;
      head.append(buf, static_cast<std::size_t>(got));
    }
    const auto sp1 = head.find(' '), sp2 = head.find(' ', sp1 + 1);
    std::string target = head.substr(sp1 + 1, sp2 - sp1 - 1);
    const std::string path = target.substr(0, target.find('?'));
    Answer a{404,
             R"({"type":"about:blank","title":"Not Found","status":404,"detail":"no route for GET )" + path +
                 R"(","category":"not_found","code":"not-found"})",
             "application/problem+json"};
    {
      std::lock_guard lock(m_);
      asked_.push_back(path);
      if (auto it = routes_.find(path); it != routes_.end()) a = it->second;
    }
    const std::string response = "HTTP/1.1 " + std::to_string(a.status) + " X\r\nContent-Type: " + a.content_type +
                                 "\r\nContent-Length: " + std::to_string(a.body.size()) + "\r\nConnection: close\r\n\r\n" + a.body;
    std::size_t sent = 0;
    while (sent < response.size()) {
      const ssize_t n = ::send(c, response.data() + sent, response.size() - sent, MSG_NOSIGNAL);
      if (n <= 0) return;
      sent += static_cast<std::size_t>(n);
    }
  }

  int fd_ = -1;
  unsigned short port_ = 0;
  std::atomic<bool> stop_{false};
  std::mutex m_;
  std::map<std::string, Answer> routes_;
  std::vector<std::string> asked_;
  std::thread thread_;
};

}  // namespace colorlab::verify::testing
