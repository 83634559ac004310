#include "colorlab/drivers/transcript.hpp"

#include <cstdio>

namespace colorlab::drivers {

std::string Transcript::escape(std::string_view bytes) {
  std::string out;
  out.reserve(bytes.size());
  for (unsigned char c : bytes) {
    if (c == '\r') {
      out += "\\r";
    } else if (c == '\n') {
      out += "\\n";
    } else if (c >= 0x20 && c < 0x7f && c != '\\') {
      out += static_cast<char>(c);
    } else {
      char buf[5];
      std::snprintf(buf, sizeof buf, "\\x%02X", c);
      out += buf;
    }
  }
  return out;
}

void Transcript::add(std::string_view direction, std::string_view bytes) {
  auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - start_).count();
  std::string line = "+" + std::to_string(ms) + "ms " + std::string(direction) + escape(bytes);
  std::lock_guard lock(mutex_);
  lines_.push_back(std::move(line));
  while (lines_.size() > capacity_) lines_.pop_front();
}

std::vector<std::string> Transcript::lines() const {
  std::lock_guard lock(mutex_);
  return {lines_.begin(), lines_.end()};
}

void Transcript::clear() {
  std::lock_guard lock(mutex_);
  lines_.clear();
}

}  // namespace colorlab::drivers
