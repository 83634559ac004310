#pragma once
// A bounded record of the bytes a driver exchanged, attached to every error so a failure at
// 3 a.m. can be diagnosed from the log without reproducing it.
#include <chrono>
#include <deque>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

namespace colorlab::drivers {

class Transcript {
 public:
  explicit Transcript(std::size_t capacity = 64) : capacity_(capacity) {}

  void sent(std::string_view bytes) { add("-> ", bytes); }
  void received(std::string_view bytes) { add("<- ", bytes); }
  void note(std::string_view text) { add("   ", text); }

  // Oldest first; each line is "+<ms> -> <escaped bytes>".
  std::vector<std::string> lines() const;
  void clear();

  static std::string escape(std::string_view bytes);

 private:
  void add(std::string_view direction, std::string_view bytes);

  std::size_t capacity_;
  mutable std::mutex mutex_;
  std::deque<std::string> lines_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace colorlab::drivers
