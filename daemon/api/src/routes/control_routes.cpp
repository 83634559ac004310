// The control lock over the API: GET /v1/control, POST /v1/control/acquire {holder, force},
// POST /v1/control/release {force}. Scope (control to take or give up the lock, admin to break
// another's) is checked before this runs, except force, which ControlLock checks.
#include "colorlab/core/error.hpp"
#include "colorlab/api/access.hpp"
#include "colorlab/api/control_lock.hpp"
#include "colorlab/protocol/api.hpp"
#include "access_body.hpp"
#include "handlers.hpp"

namespace colorlab::daemon::routes {

using nlohmann::json;

namespace {

constexpr std::size_t kMaxHolderLength = 100;

Caller caller_of(const ApiContext& ctx, const HttpRequest& req) {
  if (ctx.access) return ctx.access->caller(req);
  // Without access control (tests that build an ApiContext by hand) everyone is local.
  Caller c;
  c.transport = req.peer.transport;
  c.scope = Scope::admin;
  return c;
}

bool force_of(const json& body) {
  if (!body.contains("force")) return false;
  if (!body["force"].is_boolean()) throw Error(ErrorClass::bad_parameter, "'force' must be true or false");
  return body["force"].get<bool>();
}

// The status as this caller sees it: whether the lock is its own (the identity is the key, or
// "local" for requests without one).
json for_caller(json status, const Caller& caller) {
  json own_key = caller.key_id.empty() ? json(nullptr) : json(caller.key_id);
  status["yours"] = status.value("held", false) && status["key_id"] == own_key;
  status["you"] = caller.name();
  // What this caller may do here (read, control, admin; null: nothing), so a client such as the web
  // console can show itself read-only without probing a route that changes state.
  status["scope"] = caller.scope ? json(std::string(to_string(*caller.scope))) : json(nullptr);
  return status;
}

ControlLock& lock_of(ApiContext& ctx) {
  if (!ctx.control) throw Error(ErrorClass::unsupported, "this colorlabd has no control lock");
  return *ctx.control;
}

HttpResponse answer(const ControlLock::Outcome& o, const Caller& caller) {
  return o.ok ? HttpResponse::json(200, for_caller(o.status, caller)) : o.problem;
}

}  // namespace

HttpResponse get_control(ApiContext& ctx, const HttpRequest& req, const PathParams&) {
  ControlLock& lock = lock_of(ctx);
  return HttpResponse::json(200, for_caller(lock.status(), caller_of(ctx, req)));
}

HttpResponse post_control_acquire(ApiContext& ctx, const HttpRequest& req, const PathParams&) {
  ControlLock& lock = lock_of(ctx);
  Caller caller = caller_of(ctx, req);
  json body = access_body(req, R"({"holder": "anna at the bench"})");
  std::string holder = caller.name();
  if (body.contains("holder")) {
    if (!body["holder"].is_string() || body["holder"].get<std::string>().empty() ||
        body["holder"].get<std::string>().size() > kMaxHolderLength) {
      throw Error(ErrorClass::bad_parameter,
                  "'holder' must be a name of 1 to " + std::to_string(kMaxHolderLength) + " characters",
                  "it is what other clients are shown, e.g. \"anna at the bench\"");
    }
    holder = body["holder"].get<std::string>();
  }
  return answer(lock.acquire(caller, holder, force_of(body)), caller);
}

HttpResponse post_control_release(ApiContext& ctx, const HttpRequest& req, const PathParams&) {
  ControlLock& lock = lock_of(ctx);
  Caller caller = caller_of(ctx, req);
  json body = access_body(req, R"({"force": true})");
  return answer(lock.release(caller, force_of(body)), caller);
}

}  // namespace colorlab::daemon::routes
