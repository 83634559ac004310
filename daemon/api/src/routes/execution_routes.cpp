// Executions: POST /v1/executions (start or dry run), GET /v1/executions/{id}, and pause, resume, abort.
#include <nlohmann/json.hpp>

#include "colorlab/api/problem.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/daemon/executions.hpp"
#include "colorlab/protocol/api.hpp"
#include "handlers.hpp"

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
    return HttpResponse::json(200, ctx.executions.dry_run(body["campaign"].get<std::string>(), params));
  }
  auto record = ctx.executions.start(body["campaign"].get<std::string>(), params, req.header("idempotency-key"));
  auto r = HttpResponse::json(202, record.to_json());
  r.headers["Location"] = std::string(protocol::kPrefix) + "/executions/" + record.id;
  return r;
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
