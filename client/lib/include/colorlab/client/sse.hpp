#pragma once
// Server-Sent Events as the WHATWG spec reads them (fields id, event, data; comments; CR, LF or CRLF line
// ends), fed in whatever pieces the socket delivers.
#include <functional>
#include <string>
#include <string_view>

namespace colorlab::client {

struct SseEvent {
  std::string id;     // the last id: seen (sent back as Last-Event-ID to resume)
  std::string event;  // "message" when the event named none
  std::string data;   // data: lines joined with "\n"
};

class SseParser {
 public:
  explicit SseParser(std::function<bool(const SseEvent&)> on_event) : on_event_(std::move(on_event)) {}
  // Returns false once on_event has returned false (the caller stops reading).
  bool feed(std::string_view bytes);

 private:
  bool line(std::string_view text);
  std::function<bool(const SseEvent&)> on_event_;
  std::string pending_;
  bool after_cr_ = false;
  std::string last_id_, event_, data_;
  bool has_data_ = false;
};

}  // namespace colorlab::client
