#include "colorlab/drivers/unix_line_client.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "colorlab/core/error.hpp"

namespace colorlab::drivers {

namespace {

int millis_until(UnixLineClient::Clock::time_point deadline) {
  const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - UnixLineClient::Clock::now()).count();
  return left <= 0 ? 0 : static_cast<int>(std::min<long long>(left, 1'000'000));
}

}  // namespace

UnixLineClient::UnixLineClient(std::string what, std::size_t max_line) : what_(std::move(what)), max_line_(max_line) {}

UnixLineClient::~UnixLineClient() { close(); }

void UnixLineClient::close() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  buffer_.clear();
}

void UnixLineClient::connect(const std::string& path) {
  close();
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (path.empty() || path.size() >= sizeof addr.sun_path) {
    throw Error(ErrorClass::bad_parameter, what_ + ": socket path '" + path + "' is empty or too long",
                "Unix socket paths have at most 107 characters");
  }
  std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) throw Error(ErrorClass::io_error, what_ + ": socket(): " + std::strerror(errno));
  // Unix-socket connects complete or fail at once (EAGAIN: a listener that stopped accepting), so
  // connecting needs no deadline.
  const int rc = ::connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr);
  if (rc != 0) {
    const int err = errno;
    ::close(fd);
    throw Error(ErrorInfo{.cls = ErrorClass::no_comms,
                          .message = what_ + ": cannot connect to " + path + ": " + std::strerror(err),
                          .hint = "is the simulated lab (colorlab-sim) running, and does its announcement name this path?",
                          .transport_code = err == ENOENT ? "ENOENT" : err == ECONNREFUSED ? "ECONNREFUSED"
                                                                                           : "errno " + std::to_string(err),
                          .retryable = true});
  }
  fd_ = fd;
}

void UnixLineClient::send_line(std::string_view line, Clock::time_point deadline) {
  if (fd_ < 0) throw Error(ErrorClass::no_comms, what_ + " is not connected", "connect first");
  std::string out(line);
  out.push_back('\n');
  std::size_t sent = 0;
  while (sent < out.size()) {
    const ssize_t n = ::send(fd_, out.data() + sent, out.size() - sent, MSG_NOSIGNAL);
    if (n > 0) {
      sent += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) {
      pollfd p{fd_, POLLOUT, 0};
      if (::poll(&p, 1, millis_until(deadline)) == 0) {
        throw Error(ErrorInfo{
            .cls = ErrorClass::timeout,
            .message = what_ + ": request not accepted in time",
            .hint = "the peer stopped reading; reconnect",
            .retryable = true,
        });
      }
      continue;
    }
    const int err = errno;
    close();
    throw Error(ErrorInfo{
        .cls = ErrorClass::no_comms,
        .message = what_ + ": connection lost while sending: " + std::strerror(err),
        .hint = "the device went away (simulated unplug or colorlab-sim stopped); reconnect",
        .transport_code = err == EPIPE ? "EPIPE" : "errno " + std::to_string(err),
        .retryable = true,
    });
  }
}

std::string UnixLineClient::read_line(Clock::time_point deadline) {
  if (fd_ < 0) throw Error(ErrorClass::no_comms, what_ + " is not connected", "connect first");
  for (;;) {
    if (const auto nl = buffer_.find('\n'); nl != std::string::npos) {
      std::string line = buffer_.substr(0, nl);
      buffer_.erase(0, nl + 1);
      return line;
    }
    if (buffer_.size() > max_line_) {
      close();
      throw Error(ErrorClass::protocol_error, what_ + ": an answer longer than " + std::to_string(max_line_) + " bytes without a newline",
                  "the peer does not speak this line protocol");
    }
    pollfd p{fd_, POLLIN, 0};
    const int ready = ::poll(&p, 1, millis_until(deadline));
    if (ready == 0) {
      throw Error(ErrorInfo{
          .cls = ErrorClass::timeout,
          .message = what_ + ": no answer before the deadline",
          .hint = "the device is not answering; it may be hung or busy",
          .retryable = true,
      });
    }
    if (ready < 0 && errno == EINTR) continue;
    char chunk[16 * 1024];
    const ssize_t n = ::recv(fd_, chunk, sizeof chunk, 0);
    if (n > 0) {
      buffer_.append(chunk, static_cast<std::size_t>(n));
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
    const std::string why = n == 0 ? "the peer closed the connection" : std::strerror(errno);
    close();
    throw Error(ErrorInfo{
        .cls = ErrorClass::no_comms,
        .message = what_ + ": connection lost: " + why,
        .hint = "the device went away (simulated unplug or colorlab-sim stopped); reconnect",
        .transport_code = n == 0 ? "EOF" : "errno " + std::to_string(errno),
        .retryable = true,
    });
  }
}

}  // namespace colorlab::drivers
