#pragma once
// Every byte a bring-up session exchanges with one port, in order and timed, taken from the
// serial links' transcript taps (the links' own ring buffer keeps only the last lines).
#include <chrono>
#include <string>
#include <string_view>
#include <vector>

#include "colorlab/drivers/transcript.hpp"

namespace colorlab::bringup {

struct ByteEvent {
  enum class Kind {
    host,
    device,
    settings,
    mark
  };
  Kind kind = Kind::host;
  double t_ms = 0;   // since the recording started
  std::string data;  // raw bytes (host, device) or text (settings, mark)
};

class Recording {
 public:
  Recording() = default;
  Recording(const Recording&) = delete;
  Recording& operator=(const Recording&) = delete;

  // Records what `transcript` sees from now on. The transcript must not outlive this recording
  // with the tap still set: detach() (or the link's destruction) ends it.
  void attach(drivers::Transcript& transcript);
  static void detach(drivers::Transcript& transcript) { transcript.set_tap({}); }
  // A phase of the session ("probe ls110", "reading"), for people reading the file.
  void mark(std::string text);
  // Bytes exchanged by a link that has no Transcript tap (the relay board's HID reports).
  void host(std::string_view bytes) { add(ByteEvent::Kind::host, bytes); }
  void device(std::string_view bytes) { add(ByteEvent::Kind::device, bytes); }

  const std::vector<ByteEvent>& events() const { return events_; }
  std::size_t bytes_received() const;

 private:
  void add(ByteEvent::Kind kind, std::string_view data);

  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::vector<ByteEvent> events_;
};

}  // namespace colorlab::bringup
