#include "colorlab/api/key_failure_limit.hpp"

#include <algorithm>

namespace colorlab::daemon {

std::optional<std::chrono::seconds> KeyFailureLimit::blocked(const std::string& address, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  auto it = entries_.find(address);
  if (it == entries_.end() || !it->second.blocked_until) return std::nullopt;
  if (now >= *it->second.blocked_until) {
    // Served: the next wrong key starts a fresh count, not a block on the first failure.
    entries_.erase(it);
    return std::nullopt;
  }
  auto left = *it->second.blocked_until - now;
  auto whole = std::chrono::ceil<std::chrono::seconds>(left);
  return std::max(whole, std::chrono::seconds(1));
}

bool KeyFailureLimit::failed(const std::string& address, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  auto it = entries_.find(address);
  if (it == entries_.end()) {
    if (entries_.size() >= options_.max_addresses) prune(now);
    it = entries_.emplace(address, Entry{now, 0, std::nullopt, now}).first;
  }
  Entry& e = it->second;
  e.last_seen = now;
  if (e.blocked_until) {
    if (now < *e.blocked_until) return false;  // already refused; not counted again, the block is not extended
    e = Entry{now, 0, std::nullopt, now};
  }
  if (now - e.window_start >= options_.window) {
    e.window_start = now;
    e.failures = 0;
  }
  if (++e.failures < options_.max_failures) return false;
  e.blocked_until = now + options_.block;
  return true;
}

std::size_t KeyFailureLimit::addresses() const {
  std::lock_guard lock(mutex_);
  return entries_.size();
}

void KeyFailureLimit::prune(Clock::time_point now) {
  std::erase_if(entries_, [&](const auto& kv) {
    const Entry& e = kv.second;
    bool window_over = now - e.window_start >= options_.window;
    bool block_over = !e.blocked_until || now >= *e.blocked_until;
    return window_over && block_over;
  });
  if (entries_.size() < options_.max_addresses) return;
  // Still full of live entries: the stalest goes. Its address may guess again sooner — a bounded table is
  // worth more than a perfect count under a flood.
  auto stalest = std::min_element(entries_.begin(), entries_.end(), [](const auto& a, const auto& b) {
    return a.second.last_seen < b.second.last_seen;
  });
  entries_.erase(stalest);
}

}  // namespace colorlab::daemon
