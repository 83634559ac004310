#pragma once
// Who may do what (docs/API.md, "Access"). Scopes are ordered read < control < admin. A request's
// scope comes from how it arrived and the key it carries:
//  - the Unix socket: every scope (the socket file's permissions, 0660, are the guard);
//  - loopback TCP: `loopback_scope` without a key (read by default), the key's scope with one;
//  - any other address: nothing without a key, the key's scope with one.
// A key that is sent is always checked, on every transport: a wrong key is a mistake to report,
// not to ignore. Keys are looked up in an in-memory cache (SHA-256 → id, scope, revoked) that the
// HTTP pool threads read under a mutex; it is re-read from the store whenever keys change.
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/io_context.hpp>

#include "colorlab/api/key_failure_limit.hpp"
#include "colorlab/api/scope.hpp"
#include "colorlab/daemon/config.hpp"
#include "colorlab/http/message.hpp"
#include "colorlab/store/api_keys.hpp"
#include "colorlab/store/store.hpp"

namespace colorlab::daemon {

// The request's sender, as far as its transport and key tell.
struct Caller {
  http::Peer::Transport transport = http::Peer::Transport::loopback;
  std::optional<Scope> scope;  // none: may do nothing (a remote request without a key)
  std::string key_id;          // empty without a key
  std::string key_name;
  // Who holds the control lock: the key, or "local" for the Unix socket and keyless loopback
  // (indistinguishable to the daemon, and trusted alike).
  std::string identity() const { return key_id.empty() ? "local" : "key:" + key_id; }
  std::string name() const { return key_id.empty() ? "local" : key_name; }
  bool may(Scope needed) const { return scope && *scope >= needed; }
};

struct AccessOptions {
  Scope loopback_scope = Scope::read;
  // last_used_at is written at most this often per key: the writer's commits are precious.
  std::chrono::seconds touch_interval{60};
  // Wrong keys limited per address (key_failure_limit.hpp); `now` is injectable for tests.
  KeyFailureLimit::Options key_failures;
  std::function<KeyFailureLimit::Clock::time_point()> now = [] { return KeyFailureLimit::Clock::now(); };
};

class ControlLock;

class Access {
 public:
  // `writer` is the daemon's one writer connection, used only on `writer_thread` (reload() is
  // called there; last-used times are posted there). `control`: the lock checked after the scope.
  Access(store::Store& writer, boost::asio::any_io_executor writer_thread, AccessOptions options = {},
         ControlLock* control = nullptr);

  // Re-reads every key from the store (on the writer's thread). At start and after each change.
  void reload();

  // Every API request, on whatever thread serves it: 429 (the address sent too many wrong keys lately,
  // whatever it sends now), 401 (no, unknown or revoked key where one is
  // needed), 403 (the scope is too small), 409 (a control request while someone else holds the
  // control lock, when `gated`); nullopt lets the request through. `needed` and `gated` come from
  // the request's row in the route table (router.hpp).
  std::optional<http::HttpResponse> check(const http::HttpRequest& req, Scope needed, bool gated);
  // The same, the row found by the router (required_scope).
  std::optional<http::HttpResponse> check(const http::HttpRequest& req);

  // The sender of a request check() let through (the keys and control routes need its name).
  Caller caller(const http::HttpRequest& req) const;

  ControlLock* control() const { return control_; }

 private:
  enum class KeyState {
    none,
    ok,
    malformed,
    unknown,
    revoked
  };
  struct Identified {
    Caller caller;
    KeyState key = KeyState::none;
  };
  Identified identify(const http::HttpRequest& req) const;
  void note_use(const std::string& key_id);
  std::optional<http::HttpResponse> limit(const http::HttpRequest& req, KeyState key);

  store::Store& writer_;
  boost::asio::any_io_executor writer_thread_;
  AccessOptions options_;
  ControlLock* control_;
  KeyFailureLimit failures_;
  mutable std::mutex mutex_;
  std::map<std::string, store::ApiKeyEntry> keys_;                        // by secret SHA-256
  std::map<std::string, std::chrono::steady_clock::time_point> touched_;  // key id → last write
};

// At start-up: a listener beyond loopback without TLS is refused (Error{bad_parameter}) unless the
// configuration allows plaintext explicitly; then it is only warned about. Keys would cross the
// network in the clear.
void check_listener(const std::string& host, bool tls, bool allow_plaintext);

// colorlabd's access control for its configuration: refuses an insecure listener (check_listener),
// then builds the control lock (its events appended on `io`, the writer's thread) and the policy.
struct AccessControl {
  AccessControl();
  ~AccessControl();  // where ControlLock is complete
  AccessControl(AccessControl&&) noexcept;
  AccessControl& operator=(AccessControl&&) noexcept;
  std::unique_ptr<ControlLock> lock;
  std::unique_ptr<Access> access;
};
AccessControl make_access_control(const DaemonConfig& config, store::Store& writer, boost::asio::io_context& io);

// True for 127.0.0.0/8, ::1 and "localhost"; false for every other address or name (a name
// could resolve anywhere).
bool is_loopback_host(const std::string& host);

}  // namespace colorlab::daemon
