#pragma once
// Serial I/O for every RS-232 instrument, on Boost.Asio's serial_port. It opens real ports and the
// simulator's pseudo-terminals through the same code, so the tests exercise the production path.
// (libserialport cannot open ptys; it only enumerates real ports, see port_enumeration.hpp.)
//
// Every read and write has a deadline on the steady clock; a missed deadline cancels the I/O and
// throws Error{timeout}. Bytes are read into an internal buffer so framing never waits on an
// inter-byte timer: a reply is complete the moment its terminator arrives.
#include <chrono>
#include <memory>
#include <string>
#include <string_view>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/awaitable.hpp>
#include <boost/asio/serial_port.hpp>
#include <boost/asio/steady_timer.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/transcript.hpp"

namespace colorlab::drivers {

enum class Parity {
  none,
  even,
  odd
};
enum class FlowControl {
  none,
  hardware,
  software
};

struct SerialSettings {
  unsigned baud = 9600;
  unsigned data_bits = 8;
  Parity parity = Parity::none;
  unsigned stop_bits = 1;
  FlowControl flow = FlowControl::none;

  // Wire time of one byte at these settings (start bit + data + parity + stop bits).
  std::chrono::nanoseconds byte_time() const;
};

// "4800 7E2 none", "57600 8N1 rts/cts".
std::string describe(const SerialSettings& settings);

class SerialLink {
 public:
  using Duration = std::chrono::steady_clock::duration;

  SerialLink(boost::asio::any_io_executor executor, std::string path);
  ~SerialLink();
  SerialLink(const SerialLink&) = delete;
  SerialLink& operator=(const SerialLink&) = delete;

  // Throws Error{no_comms} with the OS reason and a hint (permissions, path).
  void open(const SerialSettings& settings);
  void reconfigure(const SerialSettings& settings);
  void close();
  bool is_open() const;

  const std::string& path() const { return path_; }
  const SerialSettings& settings() const { return settings_; }
  // Linux ptys force 8N1 whatever a driver asks for; the bytes of 7-bit protocols are unchanged.
  bool is_pty() const { return is_pty_; }

  boost::asio::awaitable<void> write(std::string_view bytes, Duration timeout);
  // Returns everything up to and including `terminator`.
  boost::asio::awaitable<std::string> read_until(std::string_view terminator, Duration timeout);
  boost::asio::awaitable<std::string> read_exactly(std::size_t count, Duration timeout);
  // Drops buffered and pending input (a stale reply must never answer the next command).
  void discard_input();

  Transcript& transcript() { return transcript_; }
  // An Error carrying this link's transcript and path.
  Error make_error(ErrorClass cls, std::string message, std::string hint = {}, std::string device_code = {},
                   std::string transport_code = {}) const;

 private:
  boost::asio::awaitable<void> fill(std::chrono::steady_clock::time_point deadline, std::string_view waiting_for);

  boost::asio::any_io_executor executor_;
  std::string path_;
  std::unique_ptr<boost::asio::serial_port> port_;
  boost::asio::steady_timer timer_;
  SerialSettings settings_;
  bool is_pty_ = false;
  std::string rx_;
  Transcript transcript_;
};

}  // namespace colorlab::drivers
