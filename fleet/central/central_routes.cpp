// Central's documents: the root, the benches, runs across benches, a run, its measurements and blobs. Each is
// the bench's document (the same record types' to_json, the same paging) plus what says which bench it is from.
#include "central_routes.hpp"

#include <nlohmann/json.hpp>

#include "colorlab/api/conditional.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/protocol/api.hpp"
#include "central_json.hpp"
#include "query.hpp"

#ifndef COLORLAB_VERSION
#define COLORLAB_VERSION "dev"
#endif

namespace colorlab::fleet::central_routes {

using nlohmann::json;
namespace dr = daemon::routes;

namespace {

std::string query_or_empty(const HttpRequest& req, const char* name) {
  auto it = req.query.find(name);
  return it == req.query.end() ? std::string() : it->second;
}

json bench_of(const CentralRun& c) { return {{"id", c.bench_id}, {"name", c.bench_name}}; }

[[noreturn]] void no_such_run(const std::string& id) {
  throw Error(ErrorClass::not_found, "central holds no run with id '" + id + "'",
              "a run arrives when its bench's colorlab-ship ships it after it ended; GET /v1/benches shows each "
              "bench's lag");
}

// An answer's key in the AnswerCache: the path and every query parameter (each can show in the answer's links),
// length-prefixed so no two requests share one.
std::string answer_key(const HttpRequest& req) {
  std::string key = req.path;
  for (const auto& [k, v] : req.query) key += "\n" + std::to_string(k.size()) + ":" + k + std::to_string(v.size()) + ":" + v;
  return key;
}

// A kept answer, or 304 when the client already holds these bytes (If-None-Match).
HttpResponse kept_answer(const HttpRequest& req, const AnswerCache::Answer& a) {
  HttpResponse r;
  r.headers["ETag"] = a.etag;
  if (auto inm = req.header("if-none-match"); inm && daemon::none_match_hits(*inm, a.etag)) {
    r.status = 304;
    return r;
  }
  r.status = 200;
  r.content_type = std::string(protocol::kContentJson);
  r.body = *a.body;
  return r;
}

HttpResponse keep_answer(CentralContext& ctx, const HttpRequest& req, const std::string& key,
                         const std::string& validator, const json& body) {
  return kept_answer(req, ctx.answers.keep(key, validator, body.dump(-1, ' ', false, json::error_handler_t::replace)));
}

}  // namespace

CentralRun require_run(Pg& pg, const std::string& id) {
  auto r = central_run(pg, id);
  if (!r) no_such_run(id);
  return *r;
}

HttpResponse get_root(CentralContext& ctx, const HttpRequest&, const PathParams&) {
  json features = json::array({"runs", "problem+json", "cursor-paging", "measurement-pages", "blobs", "exports",
                               "api-keys", "benches", "read-only"});
  return HttpResponse::json(200, {{"server", "colorlab-central"},
                                  {"server_version", COLORLAB_VERSION},
                                  {"api_version", protocol::kApiVersion},
                                  {"started_at", ctx.started_at},
                                  {"read_only", true},
                                  {"features", features},
                                  {"limits", {
                                                 {"max_request_body", protocol::kMaxRequestBody},
                                                 {"max_page_limit", protocol::kMaxPageLimit},
                                             }}});
}

HttpResponse get_benches(CentralContext& ctx, const HttpRequest&, const PathParams&) {
  auto pg = ctx.pool.lease();
  return HttpResponse::json(200, central_benches(*pg));
}

HttpResponse get_runs(CentralContext& ctx, const HttpRequest& req, const PathParams&) {
  const unsigned limit = dr::page_limit(req);
  std::optional<std::string> cursor;
  if (auto it = req.query.find("cursor"); it != req.query.end()) cursor = it->second;
  CentralRunFilter filter{query_or_empty(req, "campaign"), query_or_empty(req, "status"), query_or_empty(req, "bench"),
                          query_or_empty(req, "since"), query_or_empty(req, "until")};
  auto pg = ctx.pool.lease();
  const std::string key = answer_key(req);
  const std::string validator = central_catalog_validator(*pg);  // before the page: never newer rows than it
  if (auto kept = ctx.answers.find(key, validator)) return kept_answer(req, *kept);
  auto page = central_runs(*pg, limit, cursor, filter);
  json items = json::array();
  for (const auto& c : page.runs) {
    json j = c.run.to_json();
    j["bench"] = bench_of(c);
    items.push_back(std::move(j));
  }
  json next = nullptr;
  if (page.next_cursor) {
    std::string link = std::string(protocol::kPrefix) + "/runs?limit=" + std::to_string(limit) + "&cursor=" + *page.next_cursor;
    for (const auto& [k, v] : {std::pair<const char*, const std::string&>{"campaign", filter.campaign},
                               {"status", filter.status},
                               {"bench", filter.bench},
                               {"since", filter.since},
                               {"until", filter.until}}) {
      if (!v.empty()) link += std::string("&") + k + "=" + http::percent_encode(v);
    }
    next = link;
  }
  return keep_answer(ctx, req, key, validator,
                     {
                         {"items", items},
                         {"links", {{"next", next}}},
                         {"next_cursor", page.next_cursor ? json(*page.next_cursor) : json(nullptr)},
                     });
}

// The bench's run document plus `bench`; no report link: reports are made on a bench.
HttpResponse get_run(CentralContext& ctx, const HttpRequest&, const PathParams& params) {
  const std::string& id = params["id"];
  auto pg = ctx.pool.lease();
  const CentralRun c = require_run(*pg, id);
  json j = c.run.to_json();
  j["measurement_count"] = central_measurement_count(*pg, id);
  const std::string self = std::string(protocol::kPrefix) + "/runs/" + id;
  j["links"] = {{"measurements", self + "/measurements"}, {"blobs", self + "/blobs"}, {"export", self + "/export"}};
  j["bench"] = bench_of(c);
  return HttpResponse::json(200, j);
}

HttpResponse get_run_measurements(CentralContext& ctx, const HttpRequest& req, const PathParams& params) {
  const std::string& id = params["id"];
  const unsigned limit = dr::page_limit(req, protocol::kDefaultMeasurementPageLimit, protocol::kMaxMeasurementPageLimit);
  const std::int64_t after = dr::non_negative_query(req, "cursor", "cursor must be the next_cursor of the previous page");
  store::MeasurementFilter filter{query_or_empty(req, "step_prefix"), query_or_empty(req, "quantity"),
                                  query_or_empty(req, "instrument")};
  // A shipped run's pages never change while its row is the same (AnswerCache); the row is asked for at most
  // once per AnswerCache::kRunRecheck, so a page asked for again costs no PostgreSQL round trip at all.
  const std::string key = answer_key(req);
  const auto now = AnswerCache::Clock::now();
  std::optional<std::string> validator = ctx.answers.recent_run(id, now);
  if (validator) {
    if (auto kept = ctx.answers.find(key, *validator)) return kept_answer(req, *kept);
  }
  auto pg = ctx.pool.lease();
  if (!validator) {
    validator = central_run_validator(*pg, id);
    if (!validator) no_such_run(id);  // an unknown run is a 404, not an empty page
    ctx.answers.run_checked(id, *validator, now);
    if (auto kept = ctx.answers.find(key, *validator)) return kept_answer(req, *kept);
  }
  auto page = central_measurements_page(*pg, id, filter, after, limit);
  std::optional<std::string> next, next_link;
  if (page.next_after) {
    next = std::to_string(*page.next_after);
    std::string link = std::string(protocol::kPrefix) + "/runs/" + id + "/measurements?limit=" + std::to_string(limit) +
                       "&cursor=" + *next;
    for (const auto& [k, v] : req.query) {
      if (k != "limit" && k != "cursor") link += "&" + k + "=" + http::percent_encode(v);
    }
    next_link = link;
  }
  return kept_answer(req, ctx.answers.keep(key, *validator, measurement_page_json(page, next, next_link)));
}

HttpResponse get_run_blobs(CentralContext& ctx, const HttpRequest&, const PathParams& params) {
  const std::string& id = params["id"];
  auto pg = ctx.pool.lease();
  require_run(*pg, id);
  json items = json::array();
  for (const auto& b : central_run_blobs(*pg, id)) {
    const std::string self = std::string(protocol::kPrefix) + "/blobs/" + b.sha256;
    // No preview link: central renders no previews (the bench does, from its own files).
    items.push_back({{"name", b.name},
                     {"sha256", b.sha256},
                     {"kind", b.kind},
                     {"step", b.step},
                     {"media_type", b.blob.media_type},
                     {"size", b.blob.size},
                     {"meta", b.blob.meta},
                     {"created_at", b.created_at},
                     {"links", {{"self", self}}}});
  }
  return HttpResponse::json(200, {{"run_id", id}, {"items", items}});
}

}  // namespace colorlab::fleet::central_routes
