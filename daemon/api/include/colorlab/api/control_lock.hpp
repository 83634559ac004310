#pragma once
// The control lock (SiLA's Lock Controller): one client drives the instruments at a time, the others
// read and see who holds it. Taking it is optional — while nobody holds it, anyone with the control
// scope may drive — but while someone holds it, control requests from anyone else get 409 naming
// the holder. The holder renews it by acquiring again or by any control request of its own; a lock
// not renewed within the lease is released. The Unix socket or an admin key may break it
// (`force`). Acquired, released, broken and expired are recorded as `control` events.
//
// Thread-safe: the scope check runs on the HTTP pool threads too.
#include <chrono>
#include <functional>
#include <mutex>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "colorlab/api/access.hpp"
#include "colorlab/http/message.hpp"

namespace colorlab::daemon {

class ControlLock {
 public:
  using Clock = std::chrono::steady_clock;
  // Receives each event's payload; the daemon posts it to the writer's thread.
  using EventSink = std::function<void(const nlohmann::json&)>;

  explicit ControlLock(
      std::chrono::seconds lease, EventSink record = {},
      std::function<Clock::time_point()> now = [] { return Clock::now(); });

  struct Holder {
    std::string identity;  // "key:<id>" or "local": who may renew and release it
    std::string name;      // what others are shown
    std::string key_id;    // empty for local
    std::string since;     // ISO 8601
    Clock::time_point expires;
  };

  // {held, holder, key_id, since, expires_at, lease_s}
  nlohmann::json status();

  // Takes the lock, or renews it for its holder. Held by another: 409 naming the holder, unless
  // `force` (admin only: 403 otherwise), which breaks it. Returns the status or that problem.
  struct Outcome {
    bool ok = true;
    nlohmann::json status;       // when ok
    http::HttpResponse problem;  // when not
  };
  Outcome acquire(const Caller& caller, const std::string& name, bool force);
  // Gives the lock up. Not held: nothing to do. Held by another: 409 unless `force` (admin).
  Outcome release(const Caller& caller, bool force);

  // For a control request: 409 while another holds the lock; renews the caller's own lock.
  std::optional<http::HttpResponse> gate(const Caller& caller);

  std::chrono::seconds lease() const { return lease_; }

 private:
  // With mutex_ held: forgets an expired holder (recording it), returns the live one.
  std::optional<Holder>& current(Clock::time_point now);
  nlohmann::json status_locked(Clock::time_point now) const;
  http::HttpResponse locked_by(const Holder& h, const std::string& detail) const;
  void emit(nlohmann::json event) const;

  std::chrono::seconds lease_;
  EventSink record_;
  std::function<Clock::time_point()> now_;
  std::mutex mutex_;
  std::optional<Holder> holder_;
};

}  // namespace colorlab::daemon
