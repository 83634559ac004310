// Executions: POST /v1/executions (start or dry run), GET /v1/executions (the list, on the pool),
// GET /v1/executions/{id}, and pause, resume, abort.
#include <memory>

#include <boost/asio/awaitable.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/api/problem.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/daemon/executions.hpp"
#include "colorlab/protocol/api.hpp"
#include "handlers.hpp"
#include "query.hpp"

namespace colorlab::daemon::routes {

using nlohmann::json;

namespace {

HttpResponse control(ApiContext& ctx, const std::string& id, const std::string& action) {
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

// Parameters by value: a coroutine's frame keeps them, whatever becomes of the request.
boost::asio::awaitable<HttpResponse> dry_run_answer(ApiContext& ctx, std::string campaign, json params, std::string path) {
  try {
    auto report = ctx.executions.dry_run(campaign, params);
    const json answer = co_await std::move(report);
    co_return HttpResponse::json(200, answer);
  } catch (const Error& e) {
    co_return error_response(e, path);
  }
}

}  // namespace

HttpResponse post_execution(ApiContext& ctx, const HttpRequest& req, const PathParams&) {
  auto ct = req.header("content-type").value_or("");
  if (ct.rfind("application/json", 0) != 0) {
    return problem_response(415, "unsupported-media-type", "Unsupported media type",
                            "POST /v1/executions takes application/json, got '" + ct + "'");
  }
  json body = json::parse(req.body, nullptr, false);
  if (body.is_discarded()) {
    return problem_response(400, "bad-json", "Malformed JSON", "the request body is not valid JSON");
  }
  if (!body.is_object() || !body.contains("campaign") || !body["campaign"].is_string()) {
    return problem_response(400, "bad-request", "Invalid request",
                            "the body must be an object with a string 'campaign' (and optional 'params')",
                            "e.g. {\"campaign\": \"luminance-spot\", \"params\": {\"readings\": 3}}");
  }
  json params = body.value("params", json::object());
  if (body.contains("dry_run") && !body["dry_run"].is_boolean()) {
    return problem_response(400, "bad-request", "Invalid request", "'dry_run' must be true or false");
  }
  if (body.value("dry_run", false)) {
    // Nothing is stored and nothing moves: 200 with the dry run's report, not 202 with an execution.
    // Answered later: the io thread serves other requests while the dry run's fits run on the pool.
    HttpResponse later;
    later.later = std::make_shared<http::LaterAnswer>(http::LaterAnswer{
        [&ctx, campaign = body["campaign"].get<std::string>(), params, path = req.path] {
          return dry_run_answer(ctx, campaign, params, path);
        }});
    return later;
  }
  auto record = ctx.executions.start(body["campaign"].get<std::string>(), params, req.header("idempotency-key"));
  auto r = HttpResponse::json(202, record.to_json());
  r.headers["Location"] = std::string(protocol::kPrefix) + "/executions/" + record.id;
  return r;
}

namespace {

// ?status=running,paused: one or several execution statuses, comma-separated.
std::vector<protocol::ExecutionStatus> status_filter(const std::string& text) {
  std::vector<protocol::ExecutionStatus> out;
  std::size_t from = 0;
  while (from <= text.size()) {
    std::size_t comma = text.find(',', from);
    if (comma == std::string::npos) comma = text.size();
    std::string name = text.substr(from, comma - from);
    auto s = protocol::execution_status_from_string(name);
    if (!s)
      throw Error(ErrorClass::bad_parameter, "status '" + name + "' is not an execution status",
                  "one or several of waiting, running, paused, suspended, finished_ok, finished_error, aborted, "
                  "interrupted, comma-separated");
    out.push_back(*s);
    from = comma + 1;
  }
  return out;
}

}  // namespace

// Read from the store on the pool: a live suspension the main thread holds but has not stored yet is not
// shown here (GET /v1/executions/{id} shows it).
HttpResponse get_executions(ApiContext& ctx, const HttpRequest& req, const PathParams&) {
  unsigned limit = page_limit(req);
  std::optional<std::string> cursor;
  if (auto it = req.query.find("cursor"); it != req.query.end()) cursor = it->second;
  store::ExecutionFilter filter;
  std::string status_text;
  if (auto it = req.query.find("campaign"); it != req.query.end()) filter.campaign = it->second;
  if (auto it = req.query.find("status"); it != req.query.end()) {
    status_text = it->second;
    filter.statuses = status_filter(status_text);
  }
  auto page = ctx.reads().executions(limit, cursor, filter);
  json items = json::array();
  for (const auto& e : page.items) items.push_back(e.to_json());
  json next = nullptr;
  if (page.next_cursor) {
    std::string link = std::string(protocol::kPrefix) + "/executions?limit=" + std::to_string(limit) + "&cursor=" +
                       *page.next_cursor;
    if (!filter.campaign.empty()) link += "&campaign=" + http::percent_encode(filter.campaign);
    if (!status_text.empty()) link += "&status=" + http::percent_encode(status_text);
    next = link;
  }
  return HttpResponse::json(
      200, {{"items", items}, {"links", {{"next", next}}}, {"next_cursor", page.next_cursor ? json(*page.next_cursor) : json(nullptr)}});
}

HttpResponse get_execution(ApiContext& ctx, const HttpRequest&, const PathParams& params) {
  const std::string& id = params["id"];
  auto e = ctx.store.execution(id);
  if (!e) throw Error(ErrorClass::not_found, "no execution with id '" + id + "'");
  json j = e->to_json();
  if (auto why = ctx.executions.live_suspension(id)) {
    j["status"] = "suspended";
    j["reason"] = *why;
  }
  return HttpResponse::json(200, j);
}

HttpResponse post_execution_pause(ApiContext& ctx, const HttpRequest&, const PathParams& params) {
  return control(ctx, params["id"], "pause");
}

HttpResponse post_execution_resume(ApiContext& ctx, const HttpRequest&, const PathParams& params) {
  return control(ctx, params["id"], "resume");
}

HttpResponse post_execution_abort(ApiContext& ctx, const HttpRequest&, const PathParams& params) {
  return control(ctx, params["id"], "abort");
}

}  // namespace colorlab::daemon::routes
