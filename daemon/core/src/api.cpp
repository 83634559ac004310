#include "colorlab/daemon/api.hpp"

#include <nlohmann/json.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/daemon/access.hpp"
#include "colorlab/daemon/access_api.hpp"
#include "colorlab/daemon/blob_api.hpp"
#include "colorlab/daemon/console_files.hpp"
#include "colorlab/daemon/export_api.hpp"
#include "colorlab/daemon/queue_api.hpp"
#include "colorlab/daemon/read_connections.hpp"
#include "colorlab/daemon/report_service.hpp"
#include "colorlab/protocol/api.hpp"
#include "colorlab/protocol/problem.hpp"
#include "locate_api.hpp"
#include "report_response.hpp"

#ifndef COLORLAB_VERSION
#define COLORLAB_VERSION "dev"
#endif

namespace colorlab::daemon {

using http::HttpRequest;
using http::HttpResponse;
using nlohmann::json;

store::Store& ApiContext::reads() { return readers ? readers->for_this_thread() : store; }

namespace {

HttpResponse from_error(const Error& e, const std::string& instance) {
  auto p = protocol::problem_from_error(e);
  p.instance = instance;
  HttpResponse r;
  r.status = p.status;
  r.content_type = std::string(protocol::kContentProblem);
  r.body = p.to_json().dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);  // the instance may not be UTF-8
  return r;
}

HttpResponse method_not_allowed(const HttpRequest& req, const std::string& allowed) {
  auto r = HttpResponse::problem(405, "method-not-allowed", "Method not allowed",
                                 req.method + " is not allowed on " + req.path, "allowed: " + allowed);
  r.headers["Allow"] = allowed;
  return r;
}

unsigned page_limit(const HttpRequest& req, unsigned fallback = protocol::kDefaultPageLimit,
                    unsigned most = protocol::kMaxPageLimit) {
  auto it = req.query.find("limit");
  if (it == req.query.end()) return fallback;
  try {
    std::size_t used = 0;
    long v = std::stol(it->second, &used);
    if (used != it->second.size() || v < 1 || v > static_cast<long>(most)) throw std::out_of_range("limit");
    return static_cast<unsigned>(v);
  } catch (const std::exception&) {
    throw Error(ErrorClass::bad_parameter, "limit must be an integer from 1 to " + std::to_string(most));
  }
}

HttpResponse get_root(ApiContext& ctx) {
  json features = json::array({"instruments", "ports", "events", "campaigns", "lua-campaigns", "executions",
                               "execution-control", "resume-after-restart", "runs", "run-script", "problem+json",
                               "cursor-paging", "idempotency-key", "operator-requests", "queue", "measurement-pages",
                               "event-stream", "blobs", "locate-chart", "exports", "api-keys", "control-lock", "tls"});
  return HttpResponse::json(200, {{"server", "colorlabd"},
                                  {"server_version", COLORLAB_VERSION},
                                  {"api_version", protocol::kApiVersion},
                                  {"started_at", ctx.started_at},
                                  {"simulated_lab", ctx.simulated_lab},
                                  {"running_executions", ctx.executions.running()},
                                  {"features", features},
                                  {"limits", {{"max_request_body", protocol::kMaxRequestBody},
                                              {"max_page_limit", protocol::kMaxPageLimit}}}});
}

HttpResponse get_instruments(ApiContext& ctx) {
  return HttpResponse::json(200, {{"items", ctx.instruments.describe_all()}});
}

HttpResponse get_campaigns(ApiContext& ctx) {
  // Re-read on every request: a script dropped into the campaigns directory appears at once.
  ctx.catalogue.refresh();
  json items = json::array();
  for (const auto& c : ctx.catalogue.all()) items.push_back(c->to_json());
  for (const auto& s : ctx.catalogue.sequences()) items.push_back(s->to_json());  // kind "sequence"
  json broken = json::array();
  for (const auto& b : ctx.catalogue.broken()) broken.push_back({{"path", b.path.string()}, {"error", b.error}});
  json dirs = json::array();
  for (const auto& d : ctx.catalogue.directories()) dirs.push_back({{"path", d.path.string()}, {"origin", d.origin}});
  return HttpResponse::json(200, {{"items", items}, {"broken", broken}, {"directories", dirs}});
}

HttpResponse post_execution_control(ApiContext& ctx, const std::string& id, const std::string& action) {
  store::ExecutionRecord record;
  if (action == "pause") {
    record = ctx.executions.pause(id);
  } else if (action == "resume") {
    record = ctx.executions.resume(id);
  } else {
    record = ctx.executions.abort(id);
  }
  auto r = HttpResponse::json(202, record.to_json());
  r.headers["Location"] = std::string(protocol::kPrefix) + "/executions/" + id;
  return r;
}

HttpResponse get_run_script(ApiContext& ctx, const std::string& id) {
  auto& reads = ctx.reads();
  auto r = reads.run(id);
  if (!r) throw Error(ErrorClass::not_found, "no run with id '" + id + "'");
  if (r->script_sha256.empty()) throw Error(ErrorClass::not_found, "run '" + id + "' predates stored scripts");
  auto source = reads.script_source(r->script_sha256);
  if (!source) throw Error(ErrorClass::not_found, "the script of run '" + id + "' is missing");
  HttpResponse resp;
  resp.status = 200;
  resp.content_type = "text/x-lua; charset=utf-8";
  resp.body = *source;
  resp.headers["ETag"] = "\"" + r->script_sha256 + "\"";
  return resp;
}

HttpResponse post_execution(ApiContext& ctx, const HttpRequest& req) {
  auto ct = req.header("content-type").value_or("");
  if (ct.rfind("application/json", 0) != 0) {
    return HttpResponse::problem(415, "unsupported-media-type", "Unsupported media type",
                                 "POST /v1/executions takes application/json, got '" + ct + "'");
  }
  json body = json::parse(req.body, nullptr, false);
  if (body.is_discarded()) {
    return HttpResponse::problem(400, "bad-json", "Malformed JSON", "the request body is not valid JSON");
  }
  if (!body.is_object() || !body.contains("campaign") || !body["campaign"].is_string()) {
    return HttpResponse::problem(400, "bad-request", "Invalid request",
                                 "the body must be an object with a string 'campaign' (and optional 'params')",
                                 "e.g. {\"campaign\": \"luminance-spot\", \"params\": {\"readings\": 3}}");
  }
  json params = body.value("params", json::object());
  if (body.contains("dry_run") && !body["dry_run"].is_boolean()) {
    return HttpResponse::problem(400, "bad-request", "Invalid request", "'dry_run' must be true or false");
  }
  if (body.value("dry_run", false)) {
    // Nothing is stored and nothing moves: 200 with the dry run's report, not 202 with an execution.
    return HttpResponse::json(200, ctx.executions.dry_run(body["campaign"].get<std::string>(), params));
  }
  auto record = ctx.executions.start(body["campaign"].get<std::string>(), params, req.header("idempotency-key"));
  auto r = HttpResponse::json(202, record.to_json());
  r.headers["Location"] = std::string(protocol::kPrefix) + "/executions/" + record.id;
  return r;
}

HttpResponse get_execution(ApiContext& ctx, const std::string& id) {
  auto e = ctx.store.execution(id);
  if (!e) throw Error(ErrorClass::not_found, "no execution with id '" + id + "'");
  json j = e->to_json();
  if (auto why = ctx.executions.live_suspension(id)) {
    j["status"] = "suspended";
    j["reason"] = *why;
  }
  return HttpResponse::json(200, j);
}

json discovered_json(const drivers::DiscoveredInstrument& d) {
  json j{{"id", d.id}, {"kind", d.kind}, {"port", d.port}, {"from_config", d.from_rule}};
  if (!d.stable_port.empty()) j["stable_port"] = d.stable_port;
  if (d.usb_vid) j["usb_vid"] = *d.usb_vid;
  if (d.usb_pid) j["usb_pid"] = *d.usb_pid;
  if (!d.usb_serial.empty()) j["usb_serial"] = d.usb_serial;
  if (!d.product.empty()) j["product"] = d.product;
  return j;
}

HttpResponse get_ports(ApiContext& ctx) {
  json items = json::array();
  if (ctx.discovery) {
    for (const auto& d : ctx.discovery->present()) items.push_back(discovered_json(d));
  }
  return HttpResponse::json(200, {{"items", items}, {"hotplug", ctx.hotplug_status}});
}

HttpResponse get_events(ApiContext& ctx, const HttpRequest& req) {
  std::int64_t after = 0;
  if (auto it = req.query.find("after"); it != req.query.end()) {
    try {
      std::size_t used = 0;
      after = std::stoll(it->second, &used);
      if (used != it->second.size() || after < 0) throw std::invalid_argument("after");
    } catch (const std::exception&) {
      throw Error(ErrorClass::bad_parameter, "after must be a non-negative event sequence number");
    }
  }
  std::optional<std::string> topic;
  if (auto it = req.query.find("topic"); it != req.query.end()) topic = it->second;
  auto events = ctx.reads().events(after, page_limit(req), topic);
  json items = json::array();
  for (const auto& e : events) items.push_back({{"seq", e.seq}, {"time", e.time}, {"topic", e.topic}, {"payload", e.payload}});
  std::int64_t last = events.empty() ? after : events.back().seq;
  return HttpResponse::json(200, {{"items", items}, {"last_seq", last}});
}

HttpResponse get_runs(ApiContext& ctx, const HttpRequest& req) {
  unsigned limit = page_limit(req);
  std::optional<std::string> cursor;
  if (auto it = req.query.find("cursor"); it != req.query.end()) cursor = it->second;
  store::RunFilter filter;
  if (auto it = req.query.find("campaign"); it != req.query.end()) filter.campaign = it->second;
  if (auto it = req.query.find("status"); it != req.query.end()) filter.status = it->second;
  auto page = ctx.reads().runs(limit, cursor, filter);
  json items = json::array();
  for (const auto& r : page.runs) items.push_back(r.to_json());
  json links = json::object();
  if (page.next_cursor) {
    std::string next = std::string(protocol::kPrefix) + "/runs?limit=" + std::to_string(limit) + "&cursor=" + *page.next_cursor;
    if (!filter.campaign.empty()) next += "&campaign=" + http::percent_encode(filter.campaign);
    if (!filter.status.empty()) next += "&status=" + http::percent_encode(filter.status);
    links["next"] = next;
  } else {
    links["next"] = nullptr;
  }
  return HttpResponse::json(200, {{"items", items}, {"links", links}, {"next_cursor", page.next_cursor ? json(*page.next_cursor) : json(nullptr)}});
}

// The run document stays small however many measurements the run holds: they are paged.
HttpResponse get_run(ApiContext& ctx, const std::string& id) {
  auto& reads = ctx.reads();
  auto r = reads.run(id);
  if (!r) throw Error(ErrorClass::not_found, "no run with id '" + id + "'");
  json j = r->to_json();
  j["measurement_count"] = reads.measurement_count(id);
  const std::string self = std::string(protocol::kPrefix) + "/runs/" + id;
  j["links"] = {{"measurements", self + "/measurements"}, {"blobs", self + "/blobs"}, {"export", self + "/export"}};
  // A report is made of an ended run only.
  if (r->finished_at) j["links"]["report"] = self + "/report";
  return HttpResponse::json(200, j);
}

// The report is made in a child process on first request (seconds): report_response.cpp answers meanwhile.
HttpResponse get_run_report(ApiContext& ctx, const HttpRequest& req, const std::string& id) {
  auto r = ctx.reads().run(id);
  if (!r) throw Error(ErrorClass::not_found, "no run with id '" + id + "'");
  if (!r->finished_at)
    throw Error(ErrorClass::conflict, "run '" + id + "' is " + r->status + ": a report is made when the run has ended",
                "GET it again after the run has ended");
  return report_response(ctx.reports, req, id, {id}, "run " + id);
}

HttpResponse get_run_measurements(ApiContext& ctx, const HttpRequest& req, const std::string& id) {
  auto& reads = ctx.reads();
  unsigned limit = page_limit(req, protocol::kDefaultMeasurementPageLimit, protocol::kMaxMeasurementPageLimit);
  std::int64_t after = 0;
  if (auto it = req.query.find("cursor"); it != req.query.end()) {
    try {
      std::size_t used = 0;
      after = std::stoll(it->second, &used);
      if (used != it->second.size() || after < 0) throw std::invalid_argument("cursor");
    } catch (const std::exception&) {
      throw Error(ErrorClass::bad_parameter, "cursor must be the next_cursor of the previous page");
    }
  }
  store::MeasurementFilter filter;
  auto take = [&req](const char* name, std::string& into) {
    if (auto it = req.query.find(name); it != req.query.end()) into = it->second;
  };
  take("step_prefix", filter.step_prefix);
  take("quantity", filter.quantity);
  take("instrument", filter.instrument_id);
  // An unknown run is a 404, not an empty page.
  if (!reads.run(id)) throw Error(ErrorClass::not_found, "no run with id '" + id + "'");
  auto page = reads.measurements_page(id, filter, after, limit);
  json items = json::array();
  for (const auto& m : page.items) items.push_back(m.to_json());
  json next = nullptr;
  json next_link = nullptr;
  if (page.next_after) {
    next = std::to_string(*page.next_after);
    std::string link = std::string(protocol::kPrefix) + "/runs/" + id + "/measurements?limit=" + std::to_string(limit) +
                       "&cursor=" + next.get<std::string>();
    for (const auto& [k, v] : req.query) {
      if (k != "limit" && k != "cursor") link += "&" + k + "=" + http::percent_encode(v);
    }
    next_link = link;
  }
  return HttpResponse::json(200, {{"items", items}, {"next_cursor", next}, {"links", {{"next", next_link}}}});
}

}  // namespace

bool serves_stored_data(const HttpRequest& req) {
  if (is_locate_chart_path(req.path)) return true;  // reads a stored photograph; the locating is the pool's work
  if (req.method != "GET" && req.method != "HEAD") return false;
  if (wants_event_stream(req)) return false;  // its snapshot is the main thread's state
  const std::string prefix(protocol::kPrefix);
  const std::string& p = req.path;
  if (p != prefix && p.rfind(prefix + "/", 0) != 0) return true;  // the console's static files
  return p == prefix + "/runs" || p.rfind(prefix + "/runs/", 0) == 0 || p == prefix + "/events" ||
         p.rfind(prefix + "/blobs/", 0) == 0;
}

HttpResponse handle_api(ApiContext& ctx, const HttpRequest& req) {
  // HEAD is GET without the body (the server drops it), on every route that answers GET.
  if (req.method == "HEAD") {
    HttpRequest as_get = req;
    as_get.method = "GET";
    return handle_api(ctx, as_get);
  }
  if (!ctx.console_dir.empty()) {
    if (auto r = serve_console(req, ctx.console_dir)) return *r;
  }
  const std::string& p = req.path;
  const std::string prefix(protocol::kPrefix);
  try {
    if (ctx.access) {
      if (auto denied = ctx.access->check(req)) return *denied;
    }
    if (auto r = handle_access_api(ctx, req)) return *r;
    if (auto r = handle_operator_api(ctx, req)) return *r;
    if (p == prefix || p == prefix + "/") {
      if (req.method != "GET") return method_not_allowed(req, "GET, HEAD");
      return get_root(ctx);
    }
    if (p == prefix + "/instruments") {
      if (req.method != "GET") return method_not_allowed(req, "GET, HEAD");
      return get_instruments(ctx);
    }
    if (p == prefix + "/ports") {
      if (req.method != "GET") return method_not_allowed(req, "GET, HEAD");
      return get_ports(ctx);
    }
    if (wants_event_stream(req)) return get_event_stream(ctx, req);
    if (p == prefix + "/events") {
      if (req.method != "GET") return method_not_allowed(req, "GET, HEAD");
      return get_events(ctx, req);
    }
    if (p == prefix + "/campaigns") {
      if (req.method != "GET") return method_not_allowed(req, "GET, HEAD");
      return get_campaigns(ctx);
    }
    if (p == prefix + "/executions") {
      if (req.method != "POST") return method_not_allowed(req, "POST");
      return post_execution(ctx, req);
    }
    const std::string exec_prefix = prefix + "/executions/";
    if (p.rfind(exec_prefix, 0) == 0 && p.size() > exec_prefix.size() && p.find('/', exec_prefix.size()) == std::string::npos) {
      if (req.method != "GET") return method_not_allowed(req, "GET, HEAD");
      return get_execution(ctx, p.substr(exec_prefix.size()));
    }
    if (p.rfind(exec_prefix, 0) == 0) {
      auto rest = p.substr(exec_prefix.size());
      auto slash = rest.find('/');
      if (slash != std::string::npos && slash > 0) {
        std::string action = rest.substr(slash + 1);
        if (action == "pause" || action == "resume" || action == "abort") {
          if (req.method != "POST") return method_not_allowed(req, "POST");
          return post_execution_control(ctx, rest.substr(0, slash), action);
        }
      }
    }
    if (auto queue = handle_queue_api(ctx, req)) return *queue;
    if (auto located = handle_locate_api(ctx, req)) return *located;
    if (auto blob = handle_blob_api(ctx, req)) return *blob;
    if (auto exported = handle_export_api(ctx, req)) return *exported;
    if (p == prefix + "/runs") {
      if (req.method != "GET") return method_not_allowed(req, "GET, HEAD");
      return get_runs(ctx, req);
    }
    const std::string run_prefix = prefix + "/runs/";
    if (p.rfind(run_prefix, 0) == 0 && p.size() > run_prefix.size() + 7 && p.ends_with("/script") &&
        p.find('/', run_prefix.size()) == p.size() - 7) {
      if (req.method != "GET") return method_not_allowed(req, "GET, HEAD");
      return get_run_script(ctx, p.substr(run_prefix.size(), p.size() - 7 - run_prefix.size()));
    }
    if (p.rfind(run_prefix, 0) == 0 && p.ends_with("/report") && p.find('/', run_prefix.size()) == p.size() - 7 &&
        p.size() > run_prefix.size() + 7) {
      if (req.method != "GET") return method_not_allowed(req, "GET, HEAD");
      return get_run_report(ctx, req, p.substr(run_prefix.size(), p.size() - 7 - run_prefix.size()));
    }
    if (p.rfind(run_prefix, 0) == 0 && p.ends_with("/measurements") &&
        p.find('/', run_prefix.size()) == p.size() - 13 && p.size() > run_prefix.size() + 13) {
      if (req.method != "GET") return method_not_allowed(req, "GET, HEAD");
      return get_run_measurements(ctx, req, p.substr(run_prefix.size(), p.size() - 13 - run_prefix.size()));
    }
    if (p.rfind(run_prefix, 0) == 0 && p.size() > run_prefix.size() && p.find('/', run_prefix.size()) == std::string::npos) {
      if (req.method != "GET") return method_not_allowed(req, "GET, HEAD");
      return get_run(ctx, p.substr(run_prefix.size()));
    }
    return HttpResponse::problem(404, "not_found", "Not found", "no route for " + req.method + " " + p,
                                 "GET /v1 lists the API's features; see docs/API.md");
  } catch (const Error& e) {
    return from_error(e, req.path);
  }
}

}  // namespace colorlab::daemon
