// Operator requests over the API: GET /v1/requests, GET /v1/requests/{id}, POST /v1/requests/{id}.
#include "colorlab/core/error.hpp"
#include "colorlab/daemon/api.hpp"
#include "colorlab/protocol/api.hpp"

namespace colorlab::daemon {

using http::HttpRequest;
using http::HttpResponse;
using nlohmann::json;

std::optional<HttpResponse> handle_operator_api(ApiContext& ctx, const HttpRequest& req) {
  const std::string base = std::string(protocol::kPrefix) + "/requests";
  const std::string& p = req.path;
  if (p != base && p.rfind(base + "/", 0) != 0) return std::nullopt;
  if (!ctx.desk) throw Error(ErrorClass::unsupported, "this colorlabd has no operator desk");
  auto not_allowed = [&](const std::string& allowed) {
    auto r = HttpResponse::problem(405, "method-not-allowed", "Method not allowed",
                                   req.method + " is not allowed on " + req.path, "allowed: " + allowed);
    r.headers["Allow"] = allowed;
    return r;
  };
  if (p == base || p == base + "/") {
    if (req.method != "GET") return not_allowed("GET");
    json items = json::array();
    for (const auto& r : ctx.desk->pending()) items.push_back(r.to_json());
    return HttpResponse::json(200, {{"items", items}});
  }
  std::string id = p.substr(base.size() + 1);
  if (id.empty() || id.find('/') != std::string::npos) {
    return HttpResponse::problem(404, "not_found", "Not found", "no route for " + req.method + " " + p);
  }
  if (req.method == "GET") {
    auto r = ctx.desk->find(id);
    if (!r) throw Error(ErrorClass::not_found, "no open operator request '" + id + "'");
    return HttpResponse::json(200, r->to_json());
  }
  if (req.method != "POST") return not_allowed("GET, POST");
  auto ct = req.header("content-type").value_or("");
  if (ct.rfind("application/json", 0) != 0) {
    return HttpResponse::problem(415, "unsupported-media-type", "Unsupported media type",
                                 "POST " + p + " takes application/json, got '" + ct + "'");
  }
  json body = json::parse(req.body, nullptr, false);
  if (body.is_discarded() || !body.is_object() || !body.contains("answer") || !body["answer"].is_string()) {
    return HttpResponse::problem(400, "bad-request", "Invalid request", "the body must be an object with a string 'answer'",
                                 "e.g. {\"answer\": \"done\", \"by\": \"anna\"}");
  }
  std::string by = body.contains("by") && body["by"].is_string() ? body["by"].get<std::string>() : "operator";
  if (by.size() > 64) by.resize(64);
  json answered = ctx.desk->answer(id, body["answer"].get<std::string>(), by).to_json();
  return HttpResponse::json(200, answered);
}

}  // namespace colorlab::daemon
