#pragma once
// colorlab-central's memory of answers it already built. What central serves changes only when a bench ships:
// a run and all its rows commit in one transaction and are never updated afterwards (a later shipment of the
// same run inserts-or-ignores, a divergent one rolls back), so a run's measurement page is the same bytes for as
// long as its `runs` row is the same row version (PostgreSQL's xmin); and the run listing changes only in a
// transaction that also moves some bench's row (its shipped position, name or backlog), so it is the same bytes
// while the `benches` rows are. Each answer is kept with the validator it was built under and is served again
// only under the same one; docs/fleet.md ("The central read API") says what each route checks and when.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>

namespace colorlab::fleet {

class AnswerCache {
 public:
  using Clock = std::chrono::steady_clock;
  // How long a run's validator, once read, is trusted without asking PostgreSQL again. Only replacing a run's
  // row by hand (deleting and re-shipping it) changes one; such a change shows within this time.
  static constexpr std::chrono::milliseconds kRunRecheck{1000};

  static constexpr std::size_t kDefaultBytes = std::size_t{64} << 20;
  AnswerCache() : AnswerCache(kDefaultBytes) {}
  explicit AnswerCache(std::size_t max_bytes) : max_bytes_(max_bytes) {}

  struct Answer {
    std::shared_ptr<const std::string> body;
    std::string etag;  // strong: a hash of the body's bytes
  };
  // The answer kept under `key` if it was built under `validator`.
  std::optional<Answer> find(const std::string& key, const std::string& validator);
  // Keeps `body` (least recently used answers go first beyond max_bytes) and returns it with its entity tag.
  Answer keep(const std::string& key, const std::string& validator, std::string body);

  // A run's validator read within kRunRecheck, or nothing (read it again and call run_checked).
  std::optional<std::string> recent_run(const std::string& run_id, Clock::time_point now);
  void run_checked(const std::string& run_id, const std::string& validator, Clock::time_point now);

  std::size_t bytes() const;

 private:
  struct Entry {
    std::string key;
    std::string validator;
    Answer answer;
  };
  struct Checked {
    std::string validator;
    Clock::time_point at;
  };
  std::size_t max_bytes_;
  mutable std::mutex mutex_;
  std::list<Entry> lru_;  // most recently used first
  std::unordered_map<std::string, std::list<Entry>::iterator> by_key_;
  std::size_t bytes_ = 0;
  std::unordered_map<std::string, Checked> runs_;
};

// The entity tag of a body: the quoted SHA-256 (hex) of its bytes, the same form as the bench's and central's
// blob tags (the same bytes give the same tag in every process and version, so a client's tag survives a restart).
std::string body_etag(const std::string& body);

}  // namespace colorlab::fleet
