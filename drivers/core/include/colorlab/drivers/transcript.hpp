#pragma once
// A bounded record of the bytes a driver exchanged, attached to every error so a failure at
// 3 a.m. can be diagnosed from the log without reproducing it.
#include <chrono>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

namespace colorlab::drivers {

class Transcript {
 public:
  explicit Transcript(std::size_t capacity = 64) : capacity_(capacity) {}

  void sent(std::string_view bytes) {
    add("-> ", bytes);
    if (tap_) tap_(Event::sent, bytes);
  }
  void received(std::string_view bytes) {
    add("<- ", bytes);
    if (tap_) tap_(Event::received, bytes);
  }
  void note(std::string_view text) { add("   ", text); }
  // Line settings as the link applied them ("4800 7E2 none"); only the tap sees these.
  void settings(std::string_view text) {
    if (tap_) tap_(Event::settings, text);
  }

  // Every byte, unbounded, to whoever records a bring-up session (colorlab doctor): the ring
  // above keeps only the last lines for error reports.
  enum class Event {
    sent,
    received,
    settings
  };
  using Tap = std::function<void(Event, std::string_view)>;
  void set_tap(Tap tap) { tap_ = std::move(tap); }

  // Oldest first; each line is "+<ms> -> <escaped bytes>".
  std::vector<std::string> lines() const;
  void clear();

  static std::string escape(std::string_view bytes);

 private:
  void add(std::string_view direction, std::string_view bytes);

  std::size_t capacity_;
  mutable std::mutex mutex_;
  std::deque<std::string> lines_;
  Tap tap_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace colorlab::drivers
