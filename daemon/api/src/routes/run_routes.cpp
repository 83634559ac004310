// Stored runs: the list, one run, its script, its measurements paged and its report. Read routes: served
// on an HTTP pool thread through ctx.reads().
#include <nlohmann/json.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/protocol/api.hpp"
#include "colorlab/verify/compare/stored.hpp"
#include "handlers.hpp"
#include "query.hpp"
#include "report_response.hpp"

namespace colorlab::daemon::routes {

using nlohmann::json;

namespace {

// A run as it reads back: a verification stored before a params field existed gets it as not recorded.
json read_back(const store::RunRecord& r) {
  json j = r.to_json();
  if (r.campaign == verify::kVerifyCampaign && j.contains("params")) j["params"] = verify::params_read_back(j["params"]);
  return j;
}

}  // namespace

HttpResponse get_runs(ApiContext& ctx, const HttpRequest& req, const PathParams&) {
  unsigned limit = page_limit(req);
  std::optional<std::string> cursor;
  if (auto it = req.query.find("cursor"); it != req.query.end()) cursor = it->second;
  store::RunFilter filter;
  if (auto it = req.query.find("campaign"); it != req.query.end()) filter.campaign = it->second;
  if (auto it = req.query.find("status"); it != req.query.end()) filter.status = it->second;
  auto page = ctx.reads().runs(limit, cursor, filter);
  json items = json::array();
  for (const auto& r : page.runs) items.push_back(read_back(r));
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
HttpResponse get_run(ApiContext& ctx, const HttpRequest&, const PathParams& params) {
  const std::string& id = params["id"];
  auto& reads = ctx.reads();
  auto r = reads.run(id);
  if (!r) throw Error(ErrorClass::not_found, "no run with id '" + id + "'");
  json j = read_back(*r);
  j["measurement_count"] = reads.measurement_count(id);
  const std::string self = std::string(protocol::kPrefix) + "/runs/" + id;
  j["links"] = {{"measurements", self + "/measurements"}, {"blobs", self + "/blobs"}, {"export", self + "/export"}};
  // A report is made of an ended run only.
  if (r->finished_at) j["links"]["report"] = self + "/report";
  return HttpResponse::json(200, j);
}

HttpResponse get_run_script(ApiContext& ctx, const HttpRequest&, const PathParams& params) {
  const std::string& id = params["id"];
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

HttpResponse get_run_measurements(ApiContext& ctx, const HttpRequest& req, const PathParams& params) {
  const std::string& id = params["id"];
  auto& reads = ctx.reads();
  unsigned limit = page_limit(req, protocol::kDefaultMeasurementPageLimit, protocol::kMaxMeasurementPageLimit);
  const std::int64_t after = non_negative_query(req, "cursor", "cursor must be the next_cursor of the previous page");
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

// The report is made in a child process on first request (seconds): report_response.cpp answers meanwhile.
HttpResponse get_run_report(ApiContext& ctx, const HttpRequest& req, const PathParams& params) {
  const std::string& id = params["id"];
  auto r = ctx.reads().run(id);
  if (!r) throw Error(ErrorClass::not_found, "no run with id '" + id + "'");
  if (!r->finished_at)
    throw Error(ErrorClass::conflict, "run '" + id + "' is " + r->status + ": a report is made when the run has ended",
                "GET it again after the run has ended");
  return report_response(ctx.reports, req, id, {id}, "run " + id);
}

}  // namespace colorlab::daemon::routes
