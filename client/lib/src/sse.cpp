#include "colorlab/client/sse.hpp"

namespace colorlab::client {

bool SseParser::feed(std::string_view bytes) {
  for (char c : bytes) {
    if (after_cr_ && c == '\n') {  // the LF of a CRLF: the line already ended at the CR
      after_cr_ = false;
      continue;
    }
    after_cr_ = c == '\r';
    if (c == '\r' || c == '\n') {
      const std::string text = std::move(pending_);
      pending_.clear();
      if (!line(text)) return false;
    } else {
      pending_ += c;
    }
  }
  return true;
}

bool SseParser::line(std::string_view text) {
  if (text.empty()) {  // a blank line dispatches the event gathered so far
    if (!has_data_) {
      event_.clear();
      return true;
    }
    SseEvent e{last_id_, event_.empty() ? "message" : event_, data_};
    event_.clear();
    data_.clear();
    has_data_ = false;
    return on_event_(e);
  }
  if (text.front() == ':') return true;  // a comment (keep-alive)
  const auto colon = text.find(':');
  std::string_view field = text.substr(0, colon);
  std::string_view value = colon == std::string_view::npos ? std::string_view() : text.substr(colon + 1);
  if (!value.empty() && value.front() == ' ') value.remove_prefix(1);
  if (field == "data") {
    if (has_data_) data_ += '\n';
    data_.append(value);
    has_data_ = true;
  } else if (field == "event") {
    event_ = std::string(value);
  } else if (field == "id") {
    if (value.find('\0') == std::string_view::npos) last_id_ = std::string(value);
  }
  return true;  // retry: and unknown fields are ignored
}

}  // namespace colorlab::client
