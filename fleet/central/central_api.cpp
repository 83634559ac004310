// Routing for colorlab-central: which bench route a request names (the daemon's own route table and matcher),
// whether central serves it, may serve it to this caller, and which handler does.
#include "colorlab/fleet/central_api.hpp"

#include "colorlab/api/access.hpp"
#include "colorlab/api/console_files.hpp"
#include "colorlab/api/problem.hpp"
#include "colorlab/api/router.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/protocol/api.hpp"
#include "central_routes.hpp"

namespace colorlab::fleet {

using http::HttpRequest;
using http::HttpResponse;

namespace {

bool is_read(const std::string& method) { return method == "GET" || method == "HEAD" || method == "OPTIONS"; }

HttpResponse read_only(const HttpRequest& req) {
  auto r = daemon::problem_response(
      405, "central-read-only", "Central is read-only",
      req.method + " " + req.path + " would change a bench; colorlab-central serves what the benches shipped and "
                                    "changes nothing",
      "send control requests (campaigns, the queue, keys, the control lock) to the bench itself, at its own URL",
      {{"instance", req.path}, {"read_only", true}});
  r.headers["Allow"] = "GET, HEAD";
  return r;
}

HttpResponse not_on_central(const HttpRequest& req) {
  return daemon::problem_response(
      404, "not-on-central", "Not served by central",
      req.path + " is a bench's live state or made on a bench; central holds the runs the benches shipped",
      "GET /v1 lists what central serves; ask the bench at its own URL for the rest",
      {{"instance", req.path}});
}

using CentralHandler = HttpResponse (*)(CentralContext&, const HttpRequest&, const daemon::PathParams&);

// The bench routes central answers, by the pattern of their row in the daemon's route table.
struct Served {
  std::string_view pattern;
  CentralHandler handler;
};
constexpr Served kServed[] = {
    {"/v1", central_routes::get_root},
    {"/v1/runs", central_routes::get_runs},
    {"/v1/runs/{id}", central_routes::get_run},
    {"/v1/runs/{id}/measurements", central_routes::get_run_measurements},
    {"/v1/runs/{id}/export", central_routes::get_run_export},
    {"/v1/runs/{id}/blobs", central_routes::get_run_blobs},
    {"/v1/blobs/{sha256}", central_routes::get_blob},
};

HttpResponse dispatch(CentralContext& ctx, const HttpRequest& req) {
  const std::string prefix(protocol::kPrefix);
  if (req.path != prefix && req.path.rfind(prefix + "/", 0) != 0) {
    if (!ctx.console_dir.empty()) {
      if (auto r = daemon::serve_console(req, ctx.console_dir)) return *r;
    }
    return daemon::problem_response(404, "not_found", "Not found", "colorlab-central serves the v1 API only",
                                    "GET /v1 lists what it serves; see docs/fleet.md", {{"instance", req.path}});
  }
  const bool benches = req.path == prefix + "/benches" || req.path == prefix + "/benches/";
  const daemon::Routed routed = daemon::route_request(req);
  if (!is_read(req.method)) {
    // A bench route (or a path a bench route has) asked to change something: say why plainly.
    if (routed.route || !routed.allow.empty() || benches) return read_only(req);
  }
  if (ctx.access) {
    if (auto denied = ctx.access->check(req, daemon::Scope::read, /*gated=*/false)) return *denied;
  }
  if (!is_read(req.method)) {
    return daemon::problem_response(404, "not_found", "Not found", "no route for " + req.method + " " + req.path,
                                    "GET /v1 lists what central serves", {{"instance", req.path}});
  }
  if (req.method == "OPTIONS") {
    HttpResponse r;
    r.status = 204;
    r.headers["Allow"] = "GET, HEAD";
    return r;
  }
  if (benches) return central_routes::get_benches(ctx, req, {});
  if (!routed.route) {
    if (!routed.allow.empty()) return read_only(req);  // e.g. GET of a POST-only path
    return daemon::problem_response(404, "not_found", "Not found", "no route for " + req.method + " " + req.path,
                                    "GET /v1 lists what central serves; see docs/fleet.md", {{"instance", req.path}});
  }
  for (const auto& s : kServed) {
    if (s.pattern == routed.route->pattern) return s.handler(ctx, req, routed.params);
  }
  return not_on_central(req);
}

}  // namespace

HttpResponse handle_central(CentralContext& ctx, const HttpRequest& req) {
  try {
    return dispatch(ctx, req);
  } catch (const Error& e) {
    return daemon::error_response(e, req.path);
  } catch (const std::exception& e) {
    return daemon::error_response(Error(ErrorClass::internal, e.what()), req.path);
  }
}

}  // namespace colorlab::fleet
