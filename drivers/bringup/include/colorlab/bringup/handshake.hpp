#pragma once
// Which instrument is on a serial port, told by each protocol's own opening exchange:
//   dmx          Enttec DMX USB Pro: label 10 (serial number), the one request a genuine widget answers
//   ls110        Konica Minolta LS-110: "MDS,04" (what PsychoPy and colorlab's driver connect with)
//   spectrolino  Spectrolino / SpectroScan: ";D024" (Argyll's table probe; a stand-alone Spectrolino
//                answers it with COM error 26), at the power-on 9600 baud and at colorlab's 57600
// Every reply, whichever probe drew it, is read by all three recognisers, so a port that answers in
// another instrument's protocol is named for what it is. Every wait has a deadline (handshake_budget()).
#include <chrono>
#include <string>
#include <vector>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/awaitable.hpp>

#include "colorlab/bringup/recording.hpp"

namespace colorlab::bringup {

// The serial instrument kinds doctor knows, in its default probing order.
const std::vector<std::string>& serial_kinds();
// "the LS-110", "the Enttec DMX USB Pro", …; throws Error{bad_parameter} for an unknown kind.
std::string instrument_name(const std::string& kind);
bool is_serial_kind(const std::string& kind);

struct Heard {
  std::string kind;    // the protocol recognised ("dmx", "ls110", "spectrolino"); empty: none
  std::string detail;  // "SpectroScan status answer", "OK00", "label 10, 4 bytes"
  unsigned baud = 0;   // the speed it answered at
};

struct HandshakeResult {
  Heard heard;
  std::string garbage;             // bytes received that no recogniser accepted
  std::vector<std::string> tried;  // "dmx @115200", "ls110 @4800 7E2", …
  std::string open_error;          // the OS's refusal, when the port could not be opened
  std::string open_hint;
};

struct HandshakeOptions {
  std::vector<std::string> order;  // kinds to try, in order (serial_kinds() when empty)
  double deadline_scale = 1.0;     // every deadline multiplied (replays on slow machines)
};

// The longest the handshakes can take on a port that answers nothing (the sum of their deadlines).
std::chrono::milliseconds handshake_budget(const HandshakeOptions& options);

// Opens `port`, tries each kind's handshake until one reply is recognised, closes the port.
boost::asio::awaitable<HandshakeResult> handshake(boost::asio::any_io_executor executor, std::string port,
                                                  HandshakeOptions options, Recording& recording);

// What the recognisers make of `bytes` (exposed for the tests).
Heard recognise(std::string_view bytes);

}  // namespace colorlab::bringup
