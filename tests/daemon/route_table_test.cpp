// The API's one route table against docs/API.md's route list, read as a newcomer reads it: every
// documented route is a row and every row is documented; a documented path asked with a method it
// does not take gets 405 whose `Allow` lists the documented methods; thread placement and scopes
// come from the rows. And the problem+json category follows the error (issue 24).
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "colorlab/api/problem.hpp"
#include "colorlab/api/route_table.hpp"
#include "colorlab/api/router.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/store/queue.hpp"

using colorlab::Error;
using colorlab::ErrorClass;
using colorlab::daemon::Placement;
using colorlab::daemon::Scope;
using colorlab::daemon::route_request;
using colorlab::daemon::route_table;
using colorlab::http::HttpRequest;
using nlohmann::json;

namespace {

std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

HttpRequest request(const std::string& method, const std::string& target) {
  HttpRequest r;
  r.method = method;
  r.target = target;
  EXPECT_TRUE(r.parse_target()) << target;
  return r;
}

// docs/API.md, "## Routes": the first cell of each row, e.g. "`GET /v1/runs/{id}`",
// "`POST /v1/executions/{id}/pause` · `/resume` · `/abort`" (the last segment replaced) or
// "`GET /v1/blobs/{sha256}` · `HEAD`" (another method on the same path). Returns path → methods.
std::map<std::string, std::set<std::string>> documented_routes() {
  const std::string doc = read_file(std::filesystem::path(COLORLAB_SOURCE_DIR) / "docs" / "API.md");
  auto begin = doc.find("\n## Routes\n");
  EXPECT_NE(begin, std::string::npos) << "docs/API.md has no '## Routes' section";
  auto end = doc.find("\n## ", begin + 1);
  std::istringstream lines(doc.substr(begin, end - begin));
  std::map<std::string, std::set<std::string>> out;
  const std::regex piece("`([^`]*)`");
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind("| `", 0) != 0) continue;
    const std::string cell = line.substr(2, line.find(" | ", 2) - 2);
    std::string method, path;
    for (auto it = std::sregex_iterator(cell.begin(), cell.end(), piece); it != std::sregex_iterator(); ++it) {
      const std::string text = (*it)[1];
      if (text.front() == '/') {  // "/resume": the previous path with its last segment replaced
        path = path.substr(0, path.rfind('/')) + text;
      } else if (text.find(' ') == std::string::npos) {  // "HEAD": the previous path
        method = text;
      } else {
        method = text.substr(0, text.find(' '));
        path = text.substr(text.find(' ') + 1);
      }
      out[path].insert(method);
    }
  }
  return out;
}

std::map<std::string, std::set<std::string>> table_routes() {
  std::map<std::string, std::set<std::string>> out;
  for (const auto& r : route_table()) out[std::string(r.pattern)].insert(std::string(r.method));
  return out;
}

// A path for a pattern: each {parameter} given a value.
std::string concrete(std::string pattern) {
  return std::regex_replace(pattern, std::regex("\\{[^}]+\\}"), "0190abcd");
}

}  // namespace

TEST(RouteTable, DocsListEveryRouteOfTheTableAndNoOther) {
  auto documented = documented_routes();
  ASSERT_GT(documented.size(), 20u) << "docs/API.md's route list was not read";
  auto table = table_routes();
  for (auto& [path, methods] : documented) {
    // HEAD is documented where a client would think of it; every GET row answers it.
    if (methods.count("HEAD")) {
      EXPECT_TRUE(methods.count("GET")) << "HEAD without GET documented for " << path;
      methods.erase("HEAD");
    }
    EXPECT_TRUE(table.count(path)) << "docs/API.md documents " << path << ", which the route table lacks";
    if (table.count(path)) {
      EXPECT_EQ(methods, table[path]) << "methods of " << path;
    }
  }
  for (const auto& [path, methods] : table) {
    EXPECT_TRUE(documented.count(path)) << "the route table serves " << path << ", which docs/API.md does not list";
  }
}

TEST(RouteTable, EachDocumentedPathRefusesAnotherMethodWith405AndItsDocumentedMethodsInAllow) {
  for (const auto& [path, methods] : documented_routes()) {
    std::set<std::string> allowed = methods;
    if (allowed.count("GET")) allowed.insert("HEAD");
    auto routed = route_request(request("PATCH", concrete(path)));
    EXPECT_EQ(routed.route, nullptr) << path;
    std::set<std::string> allow;
    std::string list = routed.allow;
    for (std::size_t at = 0; at < list.size();) {
      auto comma = list.find(", ", at);
      allow.insert(list.substr(at, comma == std::string::npos ? std::string::npos : comma - at));
      at = comma == std::string::npos ? list.size() : comma + 2;
    }
    EXPECT_EQ(allow, allowed) << path << ": Allow: " << routed.allow;
  }
}

TEST(RouteTable, LiteralSegmentsWinOverParametersAndParametersAreNamed) {
  auto start = route_request(request("POST", "/v1/queue/start"));
  ASSERT_NE(start.route, nullptr);
  EXPECT_EQ(start.route->pattern, "/v1/queue/start");
  auto group = route_request(request("GET", "/v1/queue/groups/g1"));
  ASSERT_NE(group.route, nullptr);
  EXPECT_EQ(group.route->pattern, "/v1/queue/groups/{id}");
  EXPECT_EQ(group.params["id"], "g1");
  auto check = route_request(request("GET", "/v1/blobs/check"));
  ASSERT_NE(check.route, nullptr);
  EXPECT_EQ(check.route->pattern, "/v1/blobs/check");
  auto item = route_request(request("DELETE", "/v1/queue/q7"));
  ASSERT_NE(item.route, nullptr);
  EXPECT_EQ(item.params["id"], "q7");
  // An empty segment is no parameter's value, and a path no row has is a 404 (no Allow).
  auto empty = route_request(request("POST", "/v1/executions//abort"));
  EXPECT_EQ(empty.route, nullptr);
  EXPECT_TRUE(empty.allow.empty());
  EXPECT_TRUE(route_request(request("GET", "/v1/nowhere")).allow.empty());
}

TEST(RouteTable, HeadIsServedByTheGetRowAndTheEventStreamByAccept) {
  auto head = route_request(request("HEAD", "/v1/blobs/abc"));
  ASSERT_NE(head.route, nullptr);
  EXPECT_EQ(head.route->method, "GET");
  auto sse = request("GET", "/v1/events");
  sse.headers["accept"] = "text/event-stream";
  auto stream = route_request(sse);
  ASSERT_NE(stream.route, nullptr);
  EXPECT_EQ(stream.route->pattern, "/v1/events/stream");
  // The stream's snapshot is the main thread's state; the paged log is read on the pool.
  EXPECT_EQ(stream.placement(), Placement::main);
  EXPECT_EQ(route_request(request("GET", "/v1/events")).placement(), Placement::pool);
}

// Where stored data is read (docs/API.md, "Threads and connections"), written out here from the docs.
TEST(RouteTable, StoredDataIsServedOnThePoolAndLiveStateOnTheMainThread) {
  for (const char* target : {"/v1/runs", "/v1/runs/r1", "/v1/runs/r1/measurements", "/v1/runs/r1/export",
                             "/v1/runs/r1/blobs", "/v1/runs/r1/script", "/v1/blobs/abc", "/v1/blobs/abc/preview.png",
                             "/v1/events", "/v1/executions", "/index.html"}) {
    EXPECT_EQ(route_request(request("GET", target)).placement(), Placement::pool) << target;
  }
  EXPECT_EQ(route_request(request("POST", "/v1/blobs/abc/locate-chart")).placement(), Placement::pool);
  for (const char* target : {"/v1", "/v1/instruments", "/v1/queue", "/v1/requests", "/v1/control", "/v1/keys",
                             "/v1/executions/e1", "/v1/events/stream"}) {
    EXPECT_EQ(route_request(request("GET", target)).placement(), Placement::main) << target;
  }
  EXPECT_EQ(route_request(request("POST", "/v1/executions")).placement(), Placement::main);
}

// docs/API.md, "Access": what a route needs, written out from the docs; a request no row serves
// needs what its method needs.
TEST(RouteTable, ScopesAreTheDocumentedOnes) {
  struct Case {
    const char* method;
    const char* target;
    Scope needs;
  };
  for (const Case& c : {Case{"GET", "/v1/runs", Scope::read}, Case{"HEAD", "/v1/blobs/abc", Scope::read},
                        Case{"POST", "/v1/blobs/abc/locate-chart", Scope::read},
                        Case{"POST", "/v1/executions", Scope::control}, Case{"POST", "/v1/queue/q1/move", Scope::control},
                        Case{"DELETE", "/v1/queue/q1", Scope::control}, Case{"POST", "/v1/control/acquire", Scope::control},
                        Case{"GET", "/v1/keys", Scope::admin}, Case{"DELETE", "/v1/keys/k1", Scope::admin},
                        Case{"POST", "/v1/blobs/retention", Scope::admin}, Case{"GET", "/v1/nowhere", Scope::read},
                        Case{"OPTIONS", "/v1/runs", Scope::read}, Case{"PUT", "/v1/anything", Scope::control},
                        Case{"GET", "/v1/queue/start", Scope::read}}) {
    EXPECT_EQ(route_request(request(c.method, c.target)).scope, c.needs) << c.method << " " << c.target;
  }
  // The lock's own routes answer a held lock themselves; every other control route is gated by it.
  EXPECT_TRUE(route_request(request("POST", "/v1/control/release")).route->answers_lock_itself);
  EXPECT_FALSE(route_request(request("POST", "/v1/queue/start")).route->answers_lock_itself);
}

// Console files come before the access check, by choice (router.hpp): outside /v1 is the console's.
TEST(RouteTable, PathsOutsideTheApiAreTheConsolesFiles) {
  EXPECT_TRUE(route_request(request("GET", "/")).console);
  EXPECT_TRUE(route_request(request("POST", "/index.html")).console);
  EXPECT_FALSE(route_request(request("GET", "/v1")).console);
  EXPECT_FALSE(route_request(request("GET", "/v1/runs")).console);
}

// SiLA 2's categories (docs/API.md, "Conventions"): a request's fault is validation, a busy or
// unavailable server framework, a failure inside it undefined_execution — whatever builder answers.
TEST(ProblemCategory, FollowsTheErrorNotTheBuilder) {
  auto category = [](const colorlab::http::HttpResponse& r) {
    EXPECT_EQ(r.content_type, "application/problem+json");
    return json::parse(r.body)["category"].get<std::string>();
  };
  using colorlab::daemon::error_response;
  using colorlab::daemon::problem_response;
  EXPECT_EQ(category(problem_response(503, "locator-busy", "Busy", "the daemon is locating charts", "try again")),
            "framework");
  EXPECT_EQ(category(problem_response(503, "reports-unavailable", "Reports unavailable", "no reports")), "framework");
  EXPECT_EQ(category(problem_response(500, "report-failed", "Report failed", "the child died")), "undefined_execution");
  EXPECT_EQ(category(problem_response(400, "bad-request", "Invalid request", "no")), "validation");
  EXPECT_EQ(category(problem_response(409, "control-locked", "Control lock held", "anna")), "validation");
  auto storage = error_response(Error(ErrorClass::io_error, "disk full"), "/v1/executions");
  EXPECT_EQ(storage.status, 503);
  EXPECT_EQ(category(storage), "undefined_execution");
  auto comms = error_response(Error(ErrorClass::timeout, "no answer"), "/v1/executions");
  EXPECT_EQ(comms.status, 502);
  EXPECT_EQ(category(comms), "connection");
  auto missing = error_response(Error(ErrorClass::not_found, "no run"), "/v1/runs/x");
  EXPECT_EQ(missing.status, 404);
  EXPECT_EQ(category(missing), "validation");
  EXPECT_EQ(json::parse(missing.body)["instance"], "/v1/runs/x");
  // A queue refusal keeps its own code through the same builder.
  auto conflict = error_response(colorlab::store::QueueConflict("queue-reference-ended", "it failed", "enqueue anew"),
                                 "/v1/queue");
  EXPECT_EQ(conflict.status, 409);
  EXPECT_EQ(json::parse(conflict.body)["code"], "queue-reference-ended");
  // Extension members ride along (RFC 9457 §3.2).
  auto extra = problem_response(403, "scope-insufficient", "Forbidden", "no", "", {{"required_scope", "admin"}});
  EXPECT_EQ(json::parse(extra.body)["required_scope"], "admin");
}

// One builder: the API's sources make problem+json only through problem.hpp.
TEST(ProblemCategory, TheApiHasOneProblemBuilder) {
  const auto root = std::filesystem::path(COLORLAB_SOURCE_DIR) / "daemon" / "api";
  int files = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
    if (!entry.is_regular_file() || entry.path().filename() == "problem.cpp") continue;
    const auto ext = entry.path().extension();
    if (ext != ".cpp" && ext != ".hpp") continue;
    ++files;
    const std::string text = read_file(entry.path());
    EXPECT_EQ(text.find("HttpResponse::problem("), std::string::npos) << entry.path();
    EXPECT_EQ(text.find("protocol::Problem "), std::string::npos) << entry.path();
    EXPECT_EQ(text.find("problem_from_error("), std::string::npos) << entry.path();
  }
  EXPECT_GT(files, 10);
}
