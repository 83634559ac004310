#include "colorlab/bringup/recording.hpp"

namespace colorlab::bringup {

void Recording::add(ByteEvent::Kind kind, std::string_view data) {
  auto t = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count();
  // A device's reply arrives in as many reads as the OS hands it over; one event per direction
  // change keeps the file readable and the replay indifferent to how the kernel chunked it.
  if (!events_.empty() && events_.back().kind == kind && kind == ByteEvent::Kind::device) {
    events_.back().data.append(data);
    return;
  }
  events_.push_back(ByteEvent{kind, t, std::string(data)});
}

void Recording::attach(drivers::Transcript& transcript) {
  transcript.set_tap([this](drivers::Transcript::Event e, std::string_view data) {
    switch (e) {
      case drivers::Transcript::Event::sent: add(ByteEvent::Kind::host, data); break;
      case drivers::Transcript::Event::received: add(ByteEvent::Kind::device, data); break;
      case drivers::Transcript::Event::settings: add(ByteEvent::Kind::settings, data); break;
    }
  });
}

void Recording::mark(std::string text) { add(ByteEvent::Kind::mark, text); }

std::size_t Recording::bytes_received() const {
  std::size_t n = 0;
  for (const auto& e : events_) {
    if (e.kind == ByteEvent::Kind::device) n += e.data.size();
  }
  return n;
}

}  // namespace colorlab::bringup
