// The night's queue routes under /v1/queue (docs/API.md). A refusal about references leaves as 409
// with its own code (queue-reference-unknown, -ended, -order) through the router's error_response.
#include <variant>

#include <nlohmann/json.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/daemon/night_queue.hpp"
#include "colorlab/protocol/api.hpp"
#include "colorlab/api/problem.hpp"
#include "handlers.hpp"
#include "report_response.hpp"

namespace colorlab::daemon::routes {

using nlohmann::json;

namespace {

constexpr unsigned kDefaultHistory = 20;

// The JSON object a POST carries, or the problem to answer with.
std::variant<json, HttpResponse> json_body(const HttpRequest& req, const std::string& example) {
  auto ct = req.header("content-type").value_or("");
  if (ct.rfind("application/json", 0) != 0) {
    return problem_response(415, "unsupported-media-type", "Unsupported media type",
                            req.method + " " + req.path + " takes application/json, got '" + ct + "'");
  }
  json body = json::parse(req.body, nullptr, false);
  if (body.is_discarded()) return problem_response(400, "bad-json", "Malformed JSON", "the request body is not valid JSON");
  if (!body.is_object()) {
    return problem_response(400, "bad-request", "Invalid request", "the body must be a JSON object", "e.g. " + example);
  }
  return body;
}

unsigned history_limit(const HttpRequest& req) {
  auto it = req.query.find("history");
  if (it == req.query.end()) return kDefaultHistory;
  try {
    std::size_t used = 0;
    long v = std::stol(it->second, &used);
    if (used != it->second.size() || v < 0 || v > static_cast<long>(protocol::kMaxPageLimit)) throw std::out_of_range("history");
    return static_cast<unsigned>(v);
  } catch (const std::exception&) {
    throw Error(ErrorClass::bad_parameter, "history must be an integer from 0 to " + std::to_string(protocol::kMaxPageLimit),
                "how many ended items to list, most recent first");
  }
}

HttpResponse item_response(int status, const store::QueueItem& item) {
  auto r = HttpResponse::json(status, item.to_json());
  r.headers["Location"] = std::string(protocol::kPrefix) + "/queue/" + item.id;
  return r;
}

// {"sequence": NAME, "small": bool, "overrides": {step: {key: value}}, "on_failure": ...}: the whole
// sequence queued as one group; 201 with the group (200 for a retried Idempotency-Key).
HttpResponse post_sequence(NightQueue& queue, const HttpRequest& req, const json& body, const std::string& name,
                           store::OnFailure on_failure) {
  const std::string example = R"({"sequence": "dissertation", "small": true, "overrides": {"frame-average": {"frames": 8}}})";
  if (body.contains("params") && !(body["params"].is_object() && body["params"].empty())) {
    throw Error(ErrorClass::bad_parameter, "a sequence takes 'overrides' per step, not 'params'", "e.g. " + example);
  }
  bool small = false;
  if (body.contains("small")) {
    if (!body["small"].is_boolean()) throw Error(ErrorClass::bad_parameter, "'small' must be true or false", "e.g. " + example);
    small = body["small"].get<bool>();
  }
  bool start = false;
  if (body.contains("start")) {
    if (!body["start"].is_boolean()) throw Error(ErrorClass::bad_parameter, "'start' must be true or false", "e.g. " + example);
    start = body["start"].get<bool>();
  }
  json overrides = body.value("overrides", json::object());
  auto enqueued = queue.enqueue_sequence(name, small, overrides, on_failure, req.header("idempotency-key"));
  // "start": the queue started in the same request, so a client that dies on the answer leaves a running night.
  if (start) queue.start();
  auto r = HttpResponse::json(enqueued.created ? 201 : 200, queue.describe_group(enqueued.group));
  r.headers["Location"] = std::string(protocol::kPrefix) + "/queue/groups/" + enqueued.group.id;
  return r;
}

HttpResponse post_item(NightQueue& queue, const HttpRequest& req) {
  const std::string example = R"({"campaign": "luminance-spot", "params": {"readings": 3}, "on_failure": "continue"})";
  auto parsed = json_body(req, example);
  if (auto* problem = std::get_if<HttpResponse>(&parsed)) return *problem;
  const json& body = std::get<json>(parsed);
  auto on_failure = store::OnFailure::stop;
  if (body.contains("on_failure")) {
    if (!body["on_failure"].is_string()) throw Error(ErrorClass::bad_parameter, "'on_failure' must be \"stop\" or \"continue\"");
    on_failure = store::on_failure_from_string(body["on_failure"].get<std::string>());
  }
  if (body.contains("sequence")) {
    if (!body["sequence"].is_string()) throw Error(ErrorClass::bad_parameter, "'sequence' must be a sequence's name");
    return post_sequence(queue, req, body, body["sequence"].get<std::string>(), on_failure);
  }
  if (!body.contains("campaign") || !body["campaign"].is_string()) {
    throw Error(ErrorClass::bad_parameter, "the body needs a string 'campaign'", "e.g. " + example);
  }
  // A sequence's name where a campaign's is expected queues the sequence (colorlab queue add dissertation).
  if (queue.is_sequence(body["campaign"].get<std::string>())) {
    return post_sequence(queue, req, body, body["campaign"].get<std::string>(), on_failure);
  }
  json params = body.value("params", json::object());
  if (!params.is_object()) throw Error(ErrorClass::bad_parameter, "'params' must be an object", "e.g. " + example);
  auto enqueued = queue.enqueue(body["campaign"].get<std::string>(), params, on_failure, req.header("idempotency-key"));
  // A retried POST with the same Idempotency-Key answers with the item it created the first time.
  return item_response(enqueued.created ? 201 : 200, enqueued.item);
}

HttpResponse post_move(NightQueue& queue, const HttpRequest& req, const std::string& id) {
  auto parsed = json_body(req, R"({"position": 1})");
  if (auto* problem = std::get_if<HttpResponse>(&parsed)) return *problem;
  const json& body = std::get<json>(parsed);
  if (!body.contains("position") || !body["position"].is_number_integer()) {
    throw Error(ErrorClass::bad_parameter, "the body needs an integer 'position'", "1 runs next, e.g. {\"position\": 1}");
  }
  return item_response(200, queue.move(id, body["position"].get<std::int64_t>()));
}

NightQueue& queue_of(ApiContext& ctx) {
  if (!ctx.queue) throw Error(ErrorClass::internal, "the night's queue is not running in this daemon");
  return *ctx.queue;
}

}  // namespace

HttpResponse get_queue(ApiContext& ctx, const HttpRequest& req, const PathParams&) {
  return HttpResponse::json(200, queue_of(ctx).describe(history_limit(req)));
}

HttpResponse post_queue(ApiContext& ctx, const HttpRequest& req, const PathParams&) { return post_item(queue_of(ctx), req); }

HttpResponse post_queue_start(ApiContext& ctx, const HttpRequest&, const PathParams&) {
  NightQueue& queue = queue_of(ctx);
  queue.start();
  return HttpResponse::json(200, queue.describe(kDefaultHistory));
}

HttpResponse post_queue_stop(ApiContext& ctx, const HttpRequest&, const PathParams&) {
  NightQueue& queue = queue_of(ctx);
  queue.stop();
  return HttpResponse::json(200, queue.describe(kDefaultHistory));
}

HttpResponse get_queue_item(ApiContext& ctx, const HttpRequest&, const PathParams& params) {
  return item_response(200, queue_of(ctx).item(params["id"]));
}

HttpResponse delete_queue_item(ApiContext& ctx, const HttpRequest&, const PathParams& params) {
  return item_response(200, queue_of(ctx).remove(params["id"]));
}

HttpResponse post_queue_move(ApiContext& ctx, const HttpRequest& req, const PathParams& params) {
  return post_move(queue_of(ctx), req, params["id"]);
}

HttpResponse get_queue_group(ApiContext& ctx, const HttpRequest&, const PathParams& params) {
  return HttpResponse::json(200, queue_of(ctx).group(params["id"]));
}

HttpResponse get_queue_group_report(ApiContext& ctx, const HttpRequest& req, const PathParams& params) {
  const std::string& id = params["id"];
  auto [run_ids, ended] = queue_of(ctx).group_runs(id);
  if (!ended)
    throw Error(ErrorClass::conflict, "queue group '" + id + "' is still running: its report is made when it has ended",
                "GET it again after the group's last item has ended (GET /v1/queue/groups/" + id + " says)");
  if (run_ids.empty())
    throw Error(ErrorClass::conflict, "queue group '" + id + "' finished no run: there is nothing to report",
                "GET /v1/queue/groups/" + id + " shows why its items ended");
  return report_response(ctx.reports, req, "group-" + id, run_ids, "queue group " + id);
}

}  // namespace colorlab::daemon::routes
