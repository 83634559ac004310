#include "colorlab/daemon/queue_api.hpp"

#include <variant>

#include <nlohmann/json.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/daemon/night_queue.hpp"
#include "colorlab/protocol/api.hpp"
#include "report_response.hpp"

namespace colorlab::daemon {

using http::HttpRequest;
using http::HttpResponse;
using nlohmann::json;

namespace {

constexpr unsigned kDefaultHistory = 20;

HttpResponse method_not_allowed(const HttpRequest& req, const std::string& allowed) {
  auto r = HttpResponse::problem(405, "method-not-allowed", "Method not allowed",
                                 req.method + " is not allowed on " + req.path, "allowed: " + allowed);
  r.headers["Allow"] = allowed;
  return r;
}

// The JSON object a POST carries, or the problem to answer with.
std::variant<json, HttpResponse> json_body(const HttpRequest& req, const std::string& example) {
  auto ct = req.header("content-type").value_or("");
  if (ct.rfind("application/json", 0) != 0) {
    return HttpResponse::problem(415, "unsupported-media-type", "Unsupported media type",
                                 req.method + " " + req.path + " takes application/json, got '" + ct + "'");
  }
  json body = json::parse(req.body, nullptr, false);
  if (body.is_discarded()) return HttpResponse::problem(400, "bad-json", "Malformed JSON", "the request body is not valid JSON");
  if (!body.is_object()) {
    return HttpResponse::problem(400, "bad-request", "Invalid request", "the body must be a JSON object", "e.g. " + example);
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

std::optional<HttpResponse> dispatch(ApiContext& ctx, const HttpRequest& req);

}  // namespace

// A refusal about references answers 409 with its own code (queue-reference-unknown, -ended, -order),
// so a client can tell it from another conflict.
std::optional<HttpResponse> handle_queue_api(ApiContext& ctx, const HttpRequest& req) {
  try {
    return dispatch(ctx, req);
  } catch (const store::QueueConflict& e) {
    return HttpResponse::problem(409, e.code(), "Conflict", e.what(), e.hint());
  }
}

namespace {

std::optional<HttpResponse> dispatch(ApiContext& ctx, const HttpRequest& req) {
  const std::string base = std::string(protocol::kPrefix) + "/queue";
  const std::string& p = req.path;
  if (p != base && p.rfind(base + "/", 0) != 0) return std::nullopt;
  if (!ctx.queue) throw Error(ErrorClass::internal, "the night's queue is not running in this daemon");
  NightQueue& queue = *ctx.queue;

  if (p == base || p == base + "/") {
    if (req.method == "GET") return HttpResponse::json(200, queue.describe(history_limit(req)));
    if (req.method == "POST") return post_item(queue, req);
    return method_not_allowed(req, "GET, POST");
  }
  std::string rest = p.substr(base.size() + 1);
  if (rest == "start" || rest == "stop") {
    if (req.method != "POST") return method_not_allowed(req, "POST");
    if (rest == "start") {
      queue.start();
    } else {
      queue.stop();
    }
    return HttpResponse::json(200, queue.describe(kDefaultHistory));
  }
  auto slash = rest.find('/');
  if (slash == std::string::npos) {
    if (req.method == "GET") return item_response(200, queue.item(rest));
    if (req.method == "DELETE") return item_response(200, queue.remove(rest));
    return method_not_allowed(req, "GET, DELETE");
  }
  if (rest.rfind("groups/", 0) == 0 && rest.size() > 7 && rest.find('/', 7) == std::string::npos) {
    if (req.method != "GET") return method_not_allowed(req, "GET");
    return HttpResponse::json(200, queue.group(rest.substr(7)));
  }
  if (rest.rfind("groups/", 0) == 0 && rest.ends_with("/report") && rest.find('/', 7) == rest.size() - 7 &&
      rest.size() > 14) {
    if (req.method != "GET" && req.method != "HEAD") return method_not_allowed(req, "GET, HEAD");
    const std::string id = rest.substr(7, rest.size() - 14);
    auto [run_ids, ended] = queue.group_runs(id);
    if (!ended)
      throw Error(ErrorClass::conflict, "queue group '" + id + "' is still running: its report is made when it has ended",
                  "GET it again after the group's last item has ended (GET /v1/queue/groups/" + id + " says)");
    if (run_ids.empty())
      throw Error(ErrorClass::conflict, "queue group '" + id + "' finished no run: there is nothing to report",
                  "GET /v1/queue/groups/" + id + " shows why its items ended");
    return report_response(ctx.reports, req, "group-" + id, run_ids, "queue group " + id);
  }
  if (slash > 0 && rest.substr(slash + 1) == "move") {
    if (req.method != "POST") return method_not_allowed(req, "POST");
    return post_move(queue, req, rest.substr(0, slash));
  }
  return std::nullopt;  // handle_api answers 404 with its hint
}

}  // namespace

}  // namespace colorlab::daemon
