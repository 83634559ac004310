#include "colorlab/api/router.hpp"

#include <algorithm>
#include <cstdint>
#include <optional>
#include <stdexcept>

#include "colorlab/api/access.hpp"
#include "colorlab/api/console_files.hpp"
#include "colorlab/api/problem.hpp"
#include "colorlab/api/route_table.hpp"
#include "colorlab/protocol/api.hpp"

namespace colorlab::daemon {

using http::HttpRequest;
using http::HttpResponse;

const std::string& PathParams::operator[](std::string_view name) const {
  for (const auto& [n, v] : items_) {
    if (n == name) return v;
  }
  throw std::out_of_range("no path parameter '" + std::string(name) + "'");
}

namespace {

std::vector<std::string_view> segments_of(std::string_view path) {
  std::vector<std::string_view> out;
  if (path.size() > 1 && path.back() == '/') path.remove_suffix(1);  // "/v1/queue/" is "/v1/queue"
  if (!path.empty() && path.front() == '/') path.remove_prefix(1);
  while (true) {
    auto slash = path.find('/');
    out.push_back(path.substr(0, slash));
    if (slash == std::string_view::npos) break;
    path.remove_prefix(slash + 1);
  }
  return out;
}

bool is_parameter(std::string_view segment) {
  return segment.size() > 2 && segment.front() == '{' && segment.back() == '}';
}

// The table's patterns, split once.
struct Compiled {
  const Route* route;
  std::vector<std::string_view> segments;
};

const std::vector<Compiled>& compiled() {
  static const std::vector<Compiled> all = [] {
    std::vector<Compiled> out;
    for (const auto& r : route_table()) out.push_back({&r, segments_of(r.pattern)});
    return out;
  }();
  return all;
}

// How literal a pattern is that matches `path`: one bit per segment from the left, set for a literal,
// so that the larger number wins (a literal beats a parameter at the first place they differ:
// /v1/queue/start before /v1/queue/{id}); nothing when it does not match.
std::optional<std::uint32_t> literalness(const Compiled& c, const std::vector<std::string_view>& path) {
  if (c.segments.size() != path.size() || path.size() > 32) return std::nullopt;
  std::uint32_t out = 0;
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (is_parameter(c.segments[i])) {
      if (path[i].empty()) return std::nullopt;
    } else if (c.segments[i] != path[i]) {
      return std::nullopt;
    } else {
      out |= 1u << (31 - i);
    }
  }
  return out;
}

int method_rank(std::string_view m) {
  static constexpr std::string_view order[] = {"GET", "HEAD", "POST", "PUT", "PATCH", "DELETE"};
  for (int i = 0; i < 6; ++i) {
    if (order[i] == m) return i;
  }
  return 6;
}

bool outside_api(const std::string& path) {
  const std::string prefix(protocol::kPrefix);
  return path != prefix && path.rfind(prefix + "/", 0) != 0;
}

bool wants_event_stream(const HttpRequest& req) {
  return req.header("accept").value_or("").find("text/event-stream") != std::string::npos;
}

Routed find_route(const HttpRequest& req);

HttpResponse dispatch(ApiContext& ctx, const HttpRequest& req, const Routed& routed) {
  if (!routed.route) {
    if (!routed.allow.empty()) {
      auto r = problem_response(405, "method-not-allowed", "Method not allowed",
                                req.method + " is not allowed on " + req.path, "allowed: " + routed.allow);
      r.headers["Allow"] = routed.allow;
      return r;
    }
    return problem_response(404, "not_found", "Not found", "no route for " + req.method + " " + req.path,
                            "GET /v1 lists the API's features; see docs/API.md");
  }
  try {
    // HEAD is GET without the body (the server drops it).
    if (req.method == "HEAD") {
      HttpRequest as_get = req;
      as_get.method = "GET";
      return routed.route->handler(ctx, as_get, routed.params);
    }
    return routed.route->handler(ctx, req, routed.params);
  } catch (const Error& e) {
    return error_response(e, req.path);
  }
}

}  // namespace

Placement Routed::placement() const { return route ? route->placement : Placement::pool; }

Routed route_request(const HttpRequest& req) {
  Routed out = find_route(req);
  if (out.route) {
    out.scope = out.route->scope;
  } else if (req.method != "GET" && req.method != "HEAD" && req.method != "OPTIONS") {
    // No row serves it: what its method needs. Unknown methods need control too, so nothing that
    // changes state is reached with only read.
    out.scope = Scope::control;
  }
  return out;
}

Scope required_scope(const HttpRequest& req) { return route_request(req).scope; }

namespace {

Routed find_route(const HttpRequest& req) {
  Routed out;
  if (outside_api(req.path)) {
    out.console = true;
    return out;
  }
  auto path = segments_of(req.path);
  // GET /v1/events with Accept: text/event-stream is the live stream (what a browser's EventSource asks for).
  if (path.size() == 2 && path[1] == "events" && wants_event_stream(req)) path.push_back("stream");
  const std::string_view method = req.method == "HEAD" ? std::string_view("GET") : std::string_view(req.method);
  std::uint32_t best = 0;
  std::vector<const Compiled*> at_best;
  for (const auto& c : compiled()) {
    auto l = literalness(c, path);
    if (!l) continue;
    if (at_best.empty() || *l > best) {
      best = *l;
      at_best.clear();
      at_best.push_back(&c);
    } else if (*l == best) {
      at_best.push_back(&c);
    }
  }
  for (const Compiled* c : at_best) {
    if (c->route->method != method) continue;
    out.route = c->route;
    for (std::size_t i = 0; i < path.size(); ++i) {
      if (is_parameter(c->segments[i])) out.params.add(c->segments[i].substr(1, c->segments[i].size() - 2), std::string(path[i]));
    }
    return out;
  }
  std::vector<std::string_view> methods;
  for (const Compiled* c : at_best) {
    methods.push_back(c->route->method);
    if (c->route->method == "GET") methods.push_back("HEAD");
  }
  std::sort(methods.begin(), methods.end(), [](auto a, auto b) { return method_rank(a) < method_rank(b); });
  methods.erase(std::unique(methods.begin(), methods.end()), methods.end());
  for (auto m : methods) out.allow += (out.allow.empty() ? "" : ", ") + std::string(m);
  return out;
}

}  // namespace

HttpResponse handle_api(ApiContext& ctx, const HttpRequest& req, const Routed& routed) {
  if (routed.console && !ctx.console_dir.empty()) {
    if (auto r = serve_console(req, ctx.console_dir)) return *r;
  }
  if (ctx.access) {
    const bool gated = !(routed.route && routed.route->answers_lock_itself);
    if (auto denied = ctx.access->check(req, routed.scope, gated)) return *denied;
  }
  return dispatch(ctx, req, routed);
}

HttpResponse handle_api(ApiContext& ctx, const HttpRequest& req) { return handle_api(ctx, req, route_request(req)); }

}  // namespace colorlab::daemon
