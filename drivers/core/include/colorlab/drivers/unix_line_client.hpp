#pragma once
// A blocking client for the simulated lab's line-oriented Unix sockets (the tethered DSLR, the HID
// relay), for drivers whose calls already run off the event loop (a camera's worker thread) or are
// short enough to run inline (HID feature reports). One text line out, one line back; every call
// has a steady-clock deadline, so a peer that stops answering is Error(timeout), never a hang.
// It knows nothing of what the lines mean: each driver parses its own protocol.
#include <chrono>
#include <cstddef>
#include <string>
#include <string_view>

namespace colorlab::drivers {

class UnixLineClient {
 public:
  using Clock = std::chrono::steady_clock;

  // `what` names the peer in error messages ("simulated DSLR /run/…/dslr.sock").
  explicit UnixLineClient(std::string what, std::size_t max_line = 64 * 1024);
  ~UnixLineClient();
  UnixLineClient(const UnixLineClient&) = delete;
  UnixLineClient& operator=(const UnixLineClient&) = delete;

  // Error(no_comms) when nothing listens at `path` (the peer is gone or never was).
  void connect(const std::string& path);
  void close() noexcept;
  bool is_open() const { return fd_ >= 0; }

  // Appends the '\n'. Error(no_comms) when the peer has gone (EPIPE, ECONNRESET), timeout when
  // the socket stays full past the deadline.
  void send_line(std::string_view line, Clock::time_point deadline);
  // The next line without its '\n'. Error(timeout) past the deadline, Error(no_comms) when the
  // peer closes, Error(protocol_error) for a line longer than max_line.
  std::string read_line(Clock::time_point deadline);

 private:
  std::string what_;
  std::size_t max_line_;
  int fd_ = -1;
  std::string buffer_;  // bytes received after the last line handed out
};

}  // namespace colorlab::drivers
