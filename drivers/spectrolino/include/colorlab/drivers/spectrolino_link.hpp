#pragma once
// One request/answer exchange with a Spectrolino (directly or through a SpectroScan table) on a
// SerialLink: frame, send, read up to LF (never an inter-byte timer), decode, and retry what a
// retry can fix (timeouts, garbled lines, COM errors) a bounded number of times. Errors carry the
// link's transcript. Also the baud scan and speed negotiation both devices need at connect.
#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include <boost/asio/awaitable.hpp>

#include "colorlab/drivers/serial_link.hpp"
#include "colorlab/wire/spectrolino_protocol.hpp"

namespace colorlab::drivers {

namespace sl = colorlab::wire::spectrolino;

// Argyll's per-command limits (instrument-protocols §1.3/§1.6): they bound, never pace, an exchange.
struct SpectrolinoTimeouts {
  std::chrono::milliseconds command{6000};
  std::chrono::milliseconds measure{12000};
  std::chrono::milliseconds move{10000};
  std::chrono::milliseconds init{21000};
  std::chrono::milliseconds probe{500};  // per speed during the baud scan
};

enum class SpectrolinoTopology {
  standalone,
  spectroscan,
  spectroscan_t
};

class SpectrolinoLink {
 public:
  SpectrolinoLink(SerialLink& link, SpectrolinoTimeouts timeouts, int attempts);

  // Sends `body`, returns the decoded answer body. Retries timeouts, garbled frames and COM errors
  // up to `attempts` times; a COM error that persists becomes Error{coms_fail} with its device code.
  boost::asio::awaitable<sl::Bytes> transact(const sl::Bytes& body, std::chrono::milliseconds timeout,
                                             std::string_view what, int attempts = 0);
  // Sends `body` once and returns the raw reply line, or nullopt on timeout (probes, speed changes).
  boost::asio::awaitable<std::optional<std::string>> try_once(const sl::Bytes& body, std::chrono::milliseconds timeout);

  // Scans `speeds` with no flow control until ;D024 is answered; returns the topology and speed found.
  struct Found {
    SpectrolinoTopology topology;
    unsigned baud;
  };
  boost::asio::awaitable<Found> scan(const std::vector<unsigned>& speeds);

  // Re-throws `e` with this link's transcript and port in it (wire decoders do not know the link).
  [[noreturn]] void rethrow(const Error& e) const;

  SerialLink& serial() { return link_; }
  const SpectrolinoTimeouts& timeouts() const { return timeouts_; }
  int attempts() const { return attempts_; }
  std::uint64_t commands_sent() const { return commands_; }

 private:
  SerialLink& link_;
  SpectrolinoTimeouts timeouts_;
  int attempts_;
  std::uint64_t commands_ = 0;
};

SerialSettings spectrolino_serial_settings(unsigned baud, FlowControl flow);

}  // namespace colorlab::drivers
