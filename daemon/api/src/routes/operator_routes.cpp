// Operator requests over the API: GET /v1/requests, GET /v1/requests/{id}, POST /v1/requests/{id}.
#include <nlohmann/json.hpp>

#include "colorlab/api/problem.hpp"
#include "colorlab/core/error.hpp"
#include "handlers.hpp"

namespace colorlab::daemon::routes {

using nlohmann::json;

namespace {

campaigns::OperatorDesk& desk(ApiContext& ctx) {
  if (!ctx.desk) throw Error(ErrorClass::unsupported, "this colorlabd has no operator desk");
  return *ctx.desk;
}

}  // namespace

HttpResponse get_requests(ApiContext& ctx, const HttpRequest&, const PathParams&) {
  json items = json::array();
  for (const auto& r : desk(ctx).pending()) items.push_back(r.to_json());
  return HttpResponse::json(200, {{"items", items}});
}

HttpResponse get_request(ApiContext& ctx, const HttpRequest&, const PathParams& params) {
  const std::string& id = params["id"];
  auto r = desk(ctx).find(id);
  if (!r) throw Error(ErrorClass::not_found, "no open operator request '" + id + "'");
  return HttpResponse::json(200, r->to_json());
}

HttpResponse post_request_answer(ApiContext& ctx, const HttpRequest& req, const PathParams& params) {
  const std::string& id = params["id"];
  campaigns::OperatorDesk& d = desk(ctx);
  auto ct = req.header("content-type").value_or("");
  if (ct.rfind("application/json", 0) != 0) {
    return problem_response(415, "unsupported-media-type", "Unsupported media type",
                            "POST " + req.path + " takes application/json, got '" + ct + "'");
  }
  json body = json::parse(req.body, nullptr, false);
  if (body.is_discarded() || !body.is_object() || !body.contains("answer") || !body["answer"].is_string()) {
    return problem_response(400, "bad-request", "Invalid request", "the body must be an object with a string 'answer'",
                            "e.g. {\"answer\": \"done\", \"by\": \"anna\"}");
  }
  std::string by = body.contains("by") && body["by"].is_string() ? body["by"].get<std::string>() : "operator";
  if (by.size() > 64) by.resize(64);
  json answered = d.answer(id, body["answer"].get<std::string>(), by).to_json();
  return HttpResponse::json(200, answered);
}

}  // namespace colorlab::daemon::routes
