#include "colorlab/api/access.hpp"

#include <algorithm>
#include <cctype>

#include <boost/asio/ip/address.hpp>
#include <boost/asio/post.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/core/ids.hpp"
#include "colorlab/core/log.hpp"
#include "colorlab/api/control_lock.hpp"
#include "colorlab/api/problem.hpp"
#include "colorlab/api/router.hpp"
#include "colorlab/protocol/api.hpp"

namespace colorlab::daemon {

using http::HttpRequest;
using http::HttpResponse;
using Transport = http::Peer::Transport;

std::string_view to_string(Scope s) {
  switch (s) {
    case Scope::read: return "read";
    case Scope::control: return "control";
    case Scope::admin: return "admin";
  }
  return "read";
}

std::optional<Scope> scope_from_string(std::string_view s) {
  for (auto scope : {Scope::read, Scope::control, Scope::admin}) {
    if (to_string(scope) == s) return scope;
  }
  return std::nullopt;
}

bool is_loopback_host(const std::string& host) {
  if (host == "localhost") return true;
  boost::system::error_code ec;
  auto address = boost::asio::ip::make_address(host, ec);
  return !ec && address.is_loopback();
}

void check_listener(const std::string& host, bool tls, bool allow_plaintext) {
  if (host.empty() || tls || is_loopback_host(host)) return;
  if (!allow_plaintext) {
    throw Error(ErrorClass::bad_parameter,
                "listening on " + host + " (beyond loopback) needs TLS: API keys and data would cross the network in "
                                         "the clear",
                "set [tls] certificate and private_key (docs/configuration.md), or listen on 127.0.0.1 behind a "
                "reverse proxy; [access] allow_plaintext = true accepts the risk explicitly");
  }
  log::warning("access", "listening on " + host + " without TLS (allow_plaintext = true): API keys and data cross "
                                                  "the network in the clear");
}

Access::Access(store::Store& writer, boost::asio::any_io_executor writer_thread, AccessOptions options,
               ControlLock* control)
    : writer_(writer),
      writer_thread_(std::move(writer_thread)),
      options_(std::move(options)),
      control_(control),
      failures_(options_.key_failures) {
  reload();
}

void Access::reload() {
  auto keys = store::ApiKeyStore(writer_).entries();
  std::lock_guard lock(mutex_);
  keys_ = std::move(keys);
}

namespace {

// The token of "Authorization: Bearer <token>" (RFC 6750 §2.1; the scheme is case-insensitive).
std::optional<std::string> bearer_token(const std::string& value) {
  constexpr std::string_view scheme = "bearer";
  if (value.size() <= scheme.size() || value[scheme.size()] != ' ') return std::nullopt;
  for (std::size_t i = 0; i < scheme.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(value[i])) != scheme[i]) return std::nullopt;
  }
  auto begin = value.find_first_not_of(' ', scheme.size());
  if (begin == std::string::npos) return std::nullopt;
  auto end = value.find_last_not_of(' ');
  std::string token = value.substr(begin, end - begin + 1);
  if (token.find(' ') != std::string::npos) return std::nullopt;
  return token;
}

std::string_view transport_name(Transport t) {
  switch (t) {
    case Transport::unix_socket: return "the Unix socket";
    case Transport::loopback: return "loopback";
    case Transport::remote: return "a network listener";
  }
  return "a network listener";
}

HttpResponse unauthorized(const std::string& code, const std::string& detail, bool invalid_token,
                          const nlohmann::json& extra = nlohmann::json::object()) {
  auto r = problem_response(401, code, "Unauthorized", detail,
                            "send Authorization: Bearer <key> (colorlab --key KEY or COLORLAB_API_KEY); an admin "
                            "creates keys with: colorlab keys create NAME --scope read|control|admin (over the "
                            "daemon's Unix socket)",
                            extra);
  r.headers["WWW-Authenticate"] =
      invalid_token ? R"(Bearer realm="colorlab", error="invalid_token")" : R"(Bearer realm="colorlab")";
  return r;
}

// The peer's host without its port: the limit is per machine, not per connection.
std::string host_of(const http::Peer& peer) {
  auto colon = peer.address.rfind(':');
  return colon == std::string::npos ? peer.address : peer.address.substr(0, colon);
}

HttpResponse too_many(const std::string& host, std::chrono::seconds left, const KeyFailureLimit::Options& o) {
  auto r = problem_response(
      429, "key-failures", "Too many wrong API keys",
      host + " sent " + std::to_string(o.max_failures) + " wrong API keys within " + std::to_string(o.window.count()) +
          " s; every request from it is refused for " + std::to_string(left.count()) + " s more",
      "wait for Retry-After, then send the right key (colorlab keys list over the daemon's Unix socket shows "
      "which exist); the Unix socket is never limited",
      {{"retry_after_s", left.count()}});
  r.headers["Retry-After"] = std::to_string(left.count());
  return r;
}

}  // namespace

std::optional<HttpResponse> Access::limit(const HttpRequest& req, KeyState key) {
  if (req.peer.transport == Transport::unix_socket) return std::nullopt;
  auto host = host_of(req.peer);
  auto now = options_.now();
  if (auto left = failures_.blocked(host, now)) return too_many(host, *left, failures_.options());
  if (key == KeyState::malformed || key == KeyState::unknown || key == KeyState::revoked) {
    if (failures_.failed(host, now)) {
      // Once per block, and never the key: only how many, from where, for how long.
      log::warning("access", host + " sent " + std::to_string(failures_.options().max_failures) +
                                 " wrong API keys within " + std::to_string(failures_.options().window.count()) +
                                 " s: its requests are refused (429) for " +
                                 std::to_string(failures_.options().block.count()) + " s");
    }
  }
  return std::nullopt;
}

Access::Identified Access::identify(const HttpRequest& req) const {
  Identified id;
  id.caller.transport = req.peer.transport;
  switch (req.peer.transport) {
    case Transport::unix_socket: id.caller.scope = Scope::admin; break;
    case Transport::loopback: id.caller.scope = options_.loopback_scope; break;
    case Transport::remote: break;
  }
  auto header = req.header("authorization");
  if (!header) return id;
  auto token = bearer_token(*header);
  if (!token) {
    id.key = KeyState::malformed;
    return id;
  }
  // Hashed outside the lock: the pool threads only meet in the map lookup.
  auto hash = store::api_key_sha256(*token);
  std::optional<store::ApiKeyEntry> entry;
  {
    std::lock_guard lock(mutex_);
    if (auto it = keys_.find(hash); it != keys_.end()) entry = it->second;
  }
  if (!entry) {
    id.key = KeyState::unknown;
    return id;
  }
  id.caller.key_id = entry->id;
  id.caller.key_name = entry->name;
  if (entry->revoked) {
    id.key = KeyState::revoked;
    return id;
  }
  id.key = KeyState::ok;
  auto key_scope = scope_from_string(entry->scope).value_or(Scope::read);
  if (!id.caller.scope || *id.caller.scope < key_scope) id.caller.scope = key_scope;
  return id;
}

Caller Access::caller(const HttpRequest& req) const { return identify(req).caller; }

void Access::note_use(const std::string& key_id) {
  auto now = std::chrono::steady_clock::now();
  {
    std::lock_guard lock(mutex_);
    auto [it, fresh] = touched_.try_emplace(key_id, now);
    if (!fresh) {
      if (now - it->second < options_.touch_interval) return;
      it->second = now;
    }
  }
  boost::asio::post(writer_thread_, [this, key_id, at = now_iso8601()] {
    try {
      store::ApiKeyStore(writer_).touch({{key_id, at}});
    } catch (const Error& e) {
      log::warning("access", "cannot record when key " + key_id + " was used: " + e.what());
    }
  });
}

std::optional<HttpResponse> Access::check(const HttpRequest& req) {
  auto routed = route_request(req);
  return check(req, routed.scope, !(routed.route && routed.route->answers_lock_itself));
}

std::optional<HttpResponse> Access::check(const HttpRequest& req, Scope needed, bool gated) {
  auto [caller, key] = identify(req);
  if (auto refused = limit(req, key)) return refused;
  switch (key) {
    case KeyState::malformed:
      return unauthorized("key-malformed", "the Authorization header is not \"Bearer <key>\"", true);
    case KeyState::unknown: return unauthorized("key-unknown", "the API key is not known to this daemon", true);
    case KeyState::revoked:
      return unauthorized("key-revoked", "the API key '" + caller.key_name + "' (" + caller.key_id + ") was revoked",
                          true);
    case KeyState::ok: note_use(caller.key_id); break;
    case KeyState::none: break;
  }
  if (!caller.may(needed) && caller.key_id.empty()) {
    // No key where one would help: authentication is missing (401), not a key's scope too small (403).
    return unauthorized("key-required",
                        req.method + " " + req.path + " over " + std::string(transport_name(caller.transport)) +
                            " needs an API key with the '" + std::string(to_string(needed)) + "' scope",
                        false, {{"required_scope", to_string(needed)}});
  }
  if (!caller.may(needed)) {
    auto r = problem_response(
        403, "scope-insufficient", "Forbidden",
        req.method + " " + req.path + " needs the '" + std::string(to_string(needed)) + "' scope; the key '" +
            caller.key_name + "' has '" + std::string(to_string(*caller.scope)) + "'",
        "use a key with the " + std::string(to_string(needed)) +
            " scope (colorlab --key KEY or COLORLAB_API_KEY), or the daemon's Unix socket",
        {{"required_scope", to_string(needed)}, {"scope", to_string(*caller.scope)}});
    r.headers["WWW-Authenticate"] =
        R"(Bearer realm="colorlab", error="insufficient_scope", scope=")" + std::string(to_string(needed)) + "\"";
    return r;
  }
  if (control_ && needed == Scope::control && gated) return control_->gate(caller);
  return std::nullopt;
}

AccessControl::AccessControl() = default;
AccessControl::~AccessControl() = default;
AccessControl::AccessControl(AccessControl&&) noexcept = default;
AccessControl& AccessControl::operator=(AccessControl&&) noexcept = default;

AccessControl make_access_control(const DaemonConfig& config, store::Store& writer, boost::asio::io_context& io) {
  const auto& ac = config.access;
  check_listener(config.listen_host, ac.tls_certificate && ac.tls_private_key, ac.allow_plaintext);
  AccessControl out;
  out.lock = std::make_unique<ControlLock>(
      std::chrono::seconds(static_cast<long>(ac.control_lease_s)), [&writer, &io](const nlohmann::json& event) {
        // The lock is taken on any thread; the event log is written on the writer's.
        boost::asio::post(io, [&writer, event] {
          try {
            writer.append_event("control", event);
          } catch (const Error& e) {
            log::warning("access", std::string("cannot record a control lock event: ") + e.what());
          }
        });
      });
  AccessOptions options;
  options.loopback_scope = scope_from_string(ac.loopback_scope).value_or(Scope::read);
  out.access = std::make_unique<Access>(writer, io.get_executor(), options, out.lock.get());
  return out;
}

}  // namespace colorlab::daemon
