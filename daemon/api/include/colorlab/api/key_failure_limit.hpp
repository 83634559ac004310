#pragma once
// Wrong API keys limited per address (issue 27, docs/API.md "Access"): after `max_failures` failed key
// checks within `window` from one address, that address is refused (429, Retry-After) for `block`, whatever
// it sends — a right key too. A lab user reads "blocked" as "this machine is blocked": a guesser who finds
// the key mid-block must not be let in early, and letting right keys through would tell it which guess was
// right. The Unix socket is never limited (no address; its file permissions are the guard).
//
// Time comes from the caller (steady clock in the daemon, a fake one in tests), so the unit test needs no
// sleeps. The table is bounded: entries whose window and block have passed are dropped, and beyond
// `max_addresses` the stalest is dropped first — a flood of addresses costs memory, never a lock-out.
#include <chrono>
#include <cstddef>
#include <map>
#include <mutex>
#include <optional>
#include <string>

namespace colorlab::daemon {

class KeyFailureLimit {
 public:
  using Clock = std::chrono::steady_clock;
  struct Options {
    int max_failures = 10;
    std::chrono::seconds window{60};
    std::chrono::seconds block{60};
    std::size_t max_addresses = 4096;
  };

  KeyFailureLimit() : KeyFailureLimit(Options{}) {}
  explicit KeyFailureLimit(Options options) : options_(options) {}

  // How long `address` stays refused from `now` (rounded up to whole seconds, at least 1), or nullopt.
  std::optional<std::chrono::seconds> blocked(const std::string& address, Clock::time_point now);

  // Counts one failed key check. True only for the failure that starts a block: the caller logs that once.
  bool failed(const std::string& address, Clock::time_point now);

  const Options& options() const { return options_; }
  std::size_t addresses() const;

 private:
  struct Entry {
    Clock::time_point window_start;
    int failures = 0;
    std::optional<Clock::time_point> blocked_until;
    Clock::time_point last_seen;
  };
  void prune(Clock::time_point now);

  Options options_;
  mutable std::mutex mutex_;
  std::map<std::string, Entry> entries_;
};

}  // namespace colorlab::daemon
