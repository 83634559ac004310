#include "colorlab/api/control_lock.hpp"

#include "colorlab/core/ids.hpp"
#include "colorlab/api/problem.hpp"

namespace colorlab::daemon {

using nlohmann::json;

namespace {

std::string iso_in(ControlLock::Clock::duration from_now) {
  return iso8601_utc(std::chrono::system_clock::now() +
                     std::chrono::duration_cast<std::chrono::system_clock::duration>(from_now));
}

// A key's id, or null for the Unix socket and keyless loopback (as in the status).
json key_json(const std::string& key_id) { return key_id.empty() ? json(nullptr) : json(key_id); }

http::HttpResponse force_needs_admin(const char* what) {
  return problem_response(
      403, "scope-insufficient", "Forbidden",
      std::string("breaking another client's control lock (") + what + " with force) needs the admin scope",
      "use the daemon's Unix socket or an admin key", {{"required_scope", "admin"}});
}

}  // namespace

ControlLock::ControlLock(std::chrono::seconds lease, EventSink record, std::function<Clock::time_point()> now)
    : lease_(lease), record_(std::move(record)), now_(std::move(now)) {}

void ControlLock::emit(json event) const {
  if (record_) record_(event);
}

std::optional<ControlLock::Holder>& ControlLock::current(Clock::time_point now) {
  if (holder_ && now >= holder_->expires) {
    emit({{"event", "expired"},
          {"holder", holder_->name},
          {"key_id", key_json(holder_->key_id)},
          {"since", holder_->since}});
    holder_.reset();
  }
  return holder_;
}

json ControlLock::status_locked(Clock::time_point now) const {
  json j{{"held", holder_.has_value()}, {"lease_s", lease_.count()}};
  if (holder_) {
    j["holder"] = holder_->name;
    j["key_id"] = key_json(holder_->key_id);
    j["since"] = holder_->since;
    j["expires_at"] = iso_in(holder_->expires - now);
  } else {
    j["holder"] = nullptr;
  }
  return j;
}

json ControlLock::status() {
  std::lock_guard lock(mutex_);
  auto now = now_();
  current(now);
  return status_locked(now);
}

http::HttpResponse ControlLock::locked_by(const Holder& h, const std::string& detail) const {
  return problem_response(409, "control-locked", "Control lock held",
                          detail + ": the control lock is held by '" +
                              h.name + "' since " + h.since,
                          "wait until it is released (GET /v1/control), or break it with force over the Unix socket "
                          "or with an admin key",
                          {{"holder", h.name}, {"since", h.since}});
}

ControlLock::Outcome ControlLock::acquire(const Caller& caller, const std::string& name, bool force) {
  std::lock_guard lock(mutex_);
  auto now = now_();
  auto& h = current(now);
  if (h && h->identity != caller.identity()) {
    if (!force) return {false, nullptr, locked_by(*h, "cannot acquire")};
    if (!caller.may(Scope::admin)) return {false, nullptr, force_needs_admin("acquire")};
    emit({{"event", "broken"}, {"holder", h->name}, {"key_id", key_json(h->key_id)}, {"by", name}});
    h.reset();
  }
  if (h) {
    // The holder renews; a new name replaces the old one.
    h->expires = now + lease_;
    h->name = name;
  } else {
    h = Holder{caller.identity(), name, caller.key_id, now_iso8601(), now + lease_};
    emit({{"event", "acquired"}, {"holder", name}, {"key_id", key_json(caller.key_id)}, {"since", h->since}});
  }
  return {true, status_locked(now), {}};
}

ControlLock::Outcome ControlLock::release(const Caller& caller, bool force) {
  std::lock_guard lock(mutex_);
  auto now = now_();
  auto& h = current(now);
  if (h && h->identity != caller.identity()) {
    if (!force) return {false, nullptr, locked_by(*h, "cannot release another client's lock")};
    if (!caller.may(Scope::admin)) return {false, nullptr, force_needs_admin("release")};
    emit({{"event", "broken"}, {"holder", h->name}, {"key_id", key_json(h->key_id)}, {"by", caller.name()}});
    h.reset();
  } else if (h) {
    emit({{"event", "released"}, {"holder", h->name}, {"key_id", key_json(h->key_id)}, {"since", h->since}});
    h.reset();
  }
  return {true, status_locked(now), {}};
}

std::optional<http::HttpResponse> ControlLock::gate(const Caller& caller) {
  std::lock_guard lock(mutex_);
  auto now = now_();
  auto& h = current(now);
  if (!h) return std::nullopt;
  if (h->identity != caller.identity()) return locked_by(*h, "this request drives the lab");
  h->expires = now + lease_;
  return std::nullopt;
}

}  // namespace colorlab::daemon
