#pragma once
// The v1 API's router (docs/API.md, "How a request is routed"). For each request, in this order:
//  1. a path outside /v1 is the web console's static file (console_files.hpp) — before the access
//     check, by choice: the files are public and hold no data, and a browser fetches them before
//     it has a key to send;
//  2. the route is found in the route table (route_table.hpp): the row whose pattern matches the
//     path (literal segments before parameters) and whose method is the request's;
//  3. the access check (access.hpp) with the row's scope — or, where no row serves the request,
//     the method's: GET, HEAD and OPTIONS read, any other control;
//  4. no row: 405 with `Allow` (the path's methods) or 404; else the row's handler, on the thread
//     the row names. Every error leaves as problem+json (problem.hpp).
#include <string>

#include "colorlab/api/context.hpp"
#include "colorlab/api/route.hpp"
#include "colorlab/http/message.hpp"

namespace colorlab::daemon {

// Where a request goes, found once (the daemon needs the thread before it can answer).
struct Routed {
  bool console = false;          // outside /v1: a console file
  const Route* route = nullptr;  // null: no row serves the request
  PathParams params;
  std::string allow;          // with no row: the path's methods ("GET, HEAD, POST"), empty when no path matches
  Scope scope = Scope::read;  // what the access check requires (step 3)
  // The row's; without one the pool (404, 405 and console files touch no live state).
  Placement placement() const;
};

Routed route_request(const http::HttpRequest& req);

// The scope the request needs (step 3 above), for an access check without the router.
Scope required_scope(const http::HttpRequest& req);

// The whole answer: console, access, 404/405, handler, problem+json.
http::HttpResponse handle_api(ApiContext& ctx, const http::HttpRequest& req, const Routed& routed);
http::HttpResponse handle_api(ApiContext& ctx, const http::HttpRequest& req);

}  // namespace colorlab::daemon
