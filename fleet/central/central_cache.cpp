#include "colorlab/fleet/central_cache.hpp"

#include "colorlab/fleet/s3.hpp"

namespace colorlab::fleet {

std::string body_etag(const std::string& body) { return "\"" + sha256_hex(body) + "\""; }

std::optional<AnswerCache::Answer> AnswerCache::find(const std::string& key, const std::string& validator) {
  std::lock_guard lock(mutex_);
  auto it = by_key_.find(key);
  if (it == by_key_.end() || it->second->validator != validator) return std::nullopt;
  lru_.splice(lru_.begin(), lru_, it->second);
  return it->second->answer;
}

AnswerCache::Answer AnswerCache::keep(const std::string& key, const std::string& validator, std::string body) {
  Answer a{std::make_shared<const std::string>(std::move(body)), {}};
  a.etag = body_etag(*a.body);
  const std::size_t size = a.body->size() + key.size();
  std::lock_guard lock(mutex_);
  if (auto it = by_key_.find(key); it != by_key_.end()) {
    bytes_ -= it->second->answer.body->size() + key.size();
    lru_.erase(it->second);
    by_key_.erase(it);
  }
  // An answer larger than the whole budget is served, not kept.
  if (size > max_bytes_) return a;
  lru_.push_front({key, validator, a});
  by_key_[key] = lru_.begin();
  bytes_ += size;
  while (bytes_ > max_bytes_) {
    Entry& last = lru_.back();
    bytes_ -= last.answer.body->size() + last.key.size();
    by_key_.erase(last.key);
    lru_.pop_back();
  }
  return a;
}

std::optional<std::string> AnswerCache::recent_run(const std::string& run_id, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  auto it = runs_.find(run_id);
  if (it == runs_.end() || now - it->second.at > kRunRecheck) return std::nullopt;
  return it->second.validator;
}

void AnswerCache::run_checked(const std::string& run_id, const std::string& validator, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  // Bounded like the answers: a memo per run ever asked for would grow without end on a busy catalog.
  if (runs_.size() >= 100000) runs_.clear();
  runs_[run_id] = {validator, now};
}

std::size_t AnswerCache::bytes() const {
  std::lock_guard lock(mutex_);
  return bytes_;
}

}  // namespace colorlab::fleet
