#pragma once
// One row of the API's route table (route_table.hpp): everything the router knows about a route.
// Adding a route is adding a row and writing its handler (docs/API.md, "How a request is routed").
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "colorlab/api/scope.hpp"
#include "colorlab/http/message.hpp"

namespace colorlab::daemon {

struct ApiContext;

// Where a handler runs. `pool`: on the HTTP pool's thread that read the request, through that
// thread's own read-only store connection (ctx.reads()) — for routes that read stored data only.
// `main`: posted to the daemon's main (io) thread, where live state (executions, instruments, the
// queue, the writer connection) lives and requests are handled in order.
enum class Placement {
  pool,
  main
};

// The values of a pattern's {name} segments, e.g. {"id": "0190…"} for /v1/runs/{id}.
class PathParams {
 public:
  void add(std::string_view name, std::string value) { items_.emplace_back(name, std::move(value)); }
  // The value of a parameter the route's pattern names (the table guarantees it is there).
  const std::string& operator[](std::string_view name) const;

 private:
  std::vector<std::pair<std::string_view, std::string>> items_;
};

// Errors leave a handler as colorlab::Error; the router makes them problem+json (problem.hpp).
using RouteHandler = http::HttpResponse (*)(ApiContext& ctx, const http::HttpRequest& req, const PathParams& params);

struct Route {
  std::string_view method;   // one per row; a GET row answers HEAD too (the server drops the body)
  std::string_view pattern;  // "/v1/runs/{id}/script": literal segments and {name} parameters
  Scope scope;               // the least the caller must hold (access.hpp)
  Placement placement;
  RouteHandler handler;
  // The control lock's own routes (acquire, release) answer a held lock themselves; every other
  // route needing `control` is refused with 409 while someone else holds the lock.
  bool answers_lock_itself = false;
};

}  // namespace colorlab::daemon
