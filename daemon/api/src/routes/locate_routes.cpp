// POST /v1/blobs/{sha256}/locate-chart: the chart located (and every patch sampled) in a photograph already in the
// image store, automatically or from the operator's four corners (issue 14). It changes nothing stored, so it needs
// only the read scope and runs on the HTTP pool like the other stored-data routes (the route table says so).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <thread>
#include <variant>

#include <nlohmann/json.hpp>

#include "blob_photo.hpp"
#include "chart_location_json.hpp"
#include "colorlab/analysis/chart_locate.hpp"
#include "colorlab/campaigns/run_reader.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/daemon/blob_service.hpp"
#include "colorlab/protocol/api.hpp"
#include "colorlab/store/blob_index.hpp"
#include "handlers.hpp"
#include "colorlab/api/problem.hpp"
#include "colorlab/daemon/store_run_reader.hpp"

namespace colorlab::daemon::routes {

namespace ca = analysis;
using nlohmann::json;

namespace {

const char* kCornersShape = "\"corners\": [[x1, y1], [x2, y2], [x3, y3], [x4, y4]] in the photo's pixels";

struct LocateRequest {
  ca::ChartType chart = ca::ChartType::sg140;
  ca::LocateOptions options;
  std::string reference_run;
};

HttpResponse bad_request(const std::string& detail, const std::string& hint = {}) {
  return problem_response(400, "bad-request", "Invalid request", detail,
                          hint.empty() ? std::string("{\"chart\": \"sg\" | \"cc24\", ") + kCornersShape +
                                             " (optional), \"reference_run\": a chart-read run's id (optional), \"sample_fraction\": (0, 1] (optional), "
                                             "\"min_confidence\": [0, 1] (optional)}"
                                       : hint);
}

// The request body, or the 400 that says what is wrong with it.
std::variant<LocateRequest, HttpResponse> parse_request(const HttpRequest& req) {
  LocateRequest out;
  if (req.body.empty()) return out;  // all defaults: an SG, located automatically
  const auto ct = req.header("content-type").value_or("");
  if (ct.rfind("application/json", 0) != 0)
    return problem_response(415, "unsupported-media-type", "Unsupported media type",
                            "POST " + req.path + " takes application/json, got '" + ct + "'", "send Content-Type: application/json");
  const json body = json::parse(req.body, nullptr, false);
  if (body.is_discarded()) return problem_response(400, "bad-json", "Malformed JSON", "the request body is not valid JSON", "");
  if (!body.is_object()) return bad_request("the body must be a JSON object");
  for (const auto& [key, value] : body.items()) {
    if (key != "chart" && key != "corners" && key != "reference_run" && key != "sample_fraction" && key != "min_confidence")
      return bad_request("unknown member '" + key + "'");
  }
  if (body.contains("chart")) {
    if (!body["chart"].is_string() || (body["chart"] != "sg" && body["chart"] != "cc24"))
      return bad_request("chart must be \"sg\" (ColorChecker SG) or \"cc24\" (ColorChecker 24), got " + body["chart"].dump());
    out.chart = ca::chart_type_from_string(body["chart"].get<std::string>());
  }
  if (body.contains("corners") && !body["corners"].is_null()) {
    const json& c = body["corners"];
    bool ok = c.is_array() && c.size() == 4;
    std::array<ca::Point2, 4> corners{};
    for (std::size_t i = 0; ok && i < 4; ++i) {
      ok = c[i].is_array() && c[i].size() == 2 && c[i][0].is_number() && c[i][1].is_number() &&
           std::isfinite(c[i][0].get<double>()) && std::isfinite(c[i][1].get<double>());
      if (ok) corners[i] = {c[i][0].get<double>(), c[i][1].get<double>()};
    }
    if (!ok)
      return bad_request("corners must be four [x, y] pairs of numbers, got " + c.dump().substr(0, 200),
                         std::string(kCornersShape) + ": the outer corners of the patch grid, the first patch's corner first, clockwise");
    out.options.corners = corners;
  }
  if (body.contains("reference_run") && !body["reference_run"].is_null()) {
    if (!body["reference_run"].is_string() || body["reference_run"].get<std::string>().empty())
      return bad_request("reference_run must be the id of a chart-read run of the chart, got " + body["reference_run"].dump());
    out.reference_run = body["reference_run"].get<std::string>();
  }
  auto fraction = [&](const char* key, double& into, bool zero_ok) -> std::optional<HttpResponse> {
    if (!body.contains(key)) return std::nullopt;
    const json& v = body[key];
    if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() > 1 || v.get<double>() < 0 ||
        (!zero_ok && v.get<double>() == 0))
      return bad_request(std::string(key) + " must be a number in " + (zero_ok ? "[0, 1]" : "(0, 1]") + ", got " + v.dump());
    into = v.get<double>();
    return std::nullopt;
  };
  if (auto bad = fraction("sample_fraction", out.options.sample_fraction, false)) return *bad;
  if (auto bad = fraction("min_confidence", out.options.min_confidence, true)) return *bad;
  return out;
}

// A chart-read run's luminance per patch (as characterize-camera hands it to the locator): patches as light as the
// chart's surround show no edges of their own, and only the reference tells them from a cover.
ca::ChartReference reference_from_run(ApiContext& ctx, const std::string& run_id, ca::ChartType chart) {
  StoreRunReader runs(ctx.reads());
  const json ref = campaigns::chart_reference(runs, run_id);
  if (ref.value("chart", std::string()) != ca::to_string(chart))
    throw Error(ErrorClass::bad_parameter,
                "reference_run " + run_id + " read a " + ref.value("chart", std::string("?")) + " chart, not " +
                    std::string(ca::to_string(chart)),
                "give a chart-read run of the chart in the photograph");
  const ca::ChartLayout& layout = ca::chart_layout(chart);
  ca::ChartReference out;
  out.luminance.assign(static_cast<std::size_t>(layout.size()), std::numeric_limits<double>::quiet_NaN());
  const json& ids = ref["ids"];
  const json& xyz = ref["XYZ"];
  for (std::size_t i = 0; i < ids.size() && i < xyz.size(); ++i) {
    const auto it = std::find(layout.ids.begin(), layout.ids.end(), ids[i].get<std::string>());
    if (it != layout.ids.end() && xyz[i].is_array() && xyz[i].size() == 3 && xyz[i][1].is_number())
      out.luminance[static_cast<std::size_t>(it - layout.ids.begin())] = xyz[i][1].get<double>();
  }
  return out;
}

store::BlobRecord require_blob(ApiContext& ctx, const std::string& sha256) {
  if (!store::BlobStore::is_sha256(sha256))
    throw Error(ErrorClass::not_found, "no blob named '" + sha256.substr(0, 80) + "'",
                "a blob is named by the 64 lower-case hex digits of its SHA-256 (GET /v1/runs/{id}/blobs lists a run's)");
  auto row = store::BlobIndex(ctx.reads()).blob(sha256);
  if (!row) throw Error(ErrorClass::not_found, "no blob " + sha256, "GET /v1/runs/{id}/blobs lists a run's blobs");
  return *row;
}

// Locating a full-size frame takes a core for a fraction of a second: at most half the machine's cores do it at
// once, so the pool's other threads keep serving runs and blobs meanwhile.
class LocateGate {
 public:
  bool enter() {
    const int limit = std::max(1, static_cast<int>(std::thread::hardware_concurrency() / 2));
    int now = busy_.load();
    while (now < limit) {
      if (busy_.compare_exchange_weak(now, now + 1)) return true;
    }
    return false;
  }
  void leave() { --busy_; }

 private:
  std::atomic<int> busy_{0};
};

LocateGate& gate() {
  static LocateGate g;
  return g;
}

// The locator's refusals are answers about the photograph, not about the request's syntax or the blob's existence:
// 422 with a code a client can act on, and the hint saying how to give the corners here.
HttpResponse refusal(const Error& e, const HttpRequest& req, const LocateRequest& r, const std::string& sha256) {
  const std::string chart(ca::to_string(r.chart));
  json extra{{"instance", req.path}, {"blob", sha256}, {"chart", chart}, {"locator_error", std::string(to_string(e.cls()))}};
  const std::string api_hint = std::string("; over the API give ") + kCornersShape +
                               " (the outer corners of the patch grid, the first patch's corner first, clockwise)";
  switch (e.cls()) {
    case ErrorClass::not_found:
      return problem_response(422, "chart-not-found", "Chart not found", e.info().message, e.hint() + api_hint, extra);
    case ErrorClass::needs_operator:
      return problem_response(422, "chart-needs-corners", "Chart location unsure", e.info().message,
                              e.hint().empty() ? std::string("give the chart's corners") + api_hint : e.hint() + api_hint, extra);
    case ErrorClass::bad_parameter:
      if (r.options.corners)
        return problem_response(400, "bad-corners", "Invalid corners", e.info().message,
                                e.hint().empty() ? std::string(kCornersShape) + ", inside the photo, in order around the chart" : e.hint(),
                                extra);
      throw e;
    case ErrorClass::bad_data:
      return problem_response(422, "photo-unreadable", "Photograph unreadable", e.info().message, e.hint(), extra);
    case ErrorClass::unsupported:
      return problem_response(422, "not-a-photograph", "Not a photograph", e.info().message, e.hint(), extra);
    default: throw e;
  }
}

HttpResponse post_locate(ApiContext& ctx, const HttpRequest& req, const std::string& sha256) {
  auto parsed = parse_request(req);
  if (auto* bad = std::get_if<HttpResponse>(&parsed)) return *bad;
  LocateRequest& r = std::get<LocateRequest>(parsed);
  const store::BlobRecord blob = require_blob(ctx, sha256);
  if (!r.reference_run.empty()) r.options.reference = reference_from_run(ctx, r.reference_run, r.chart);
  if (!ctx.blobs) throw Error(ErrorClass::unsupported, "this daemon keeps no blob store");
  const auto path = ctx.blobs->files().path_of(sha256);
  if (!std::filesystem::exists(path))
    throw Error(ErrorClass::not_found, "the file of blob " + sha256 + " is missing from the blob store", "GET /v1/blobs/check lists what the store lacks");
  if (!gate().enter()) {
    auto busy = problem_response(503, "locator-busy", "Busy", "the daemon is locating charts in other photographs", "try again in a second");
    busy.headers["Retry-After"] = "1";
    return busy;
  }
  struct Leave {
    ~Leave() { gate().leave(); }
  } leave;
  try {
    const BlobPhoto photo = read_blob_photo(path, blob.media_type, blob.meta);
    const ca::ChartLocation loc = ca::locate_chart(photo.view(), r.chart, r.options);
    json out = chart_location_json(loc, photo.scale);
    out["blob"] = {{"sha256", sha256},
                   {"media_type", blob.media_type},
                   {"width", photo.photo.width},
                   {"height", photo.photo.height},
                   {"mosaic", photo.cfa.has_value()},
                   {"black_level", photo.black_level}};
    return HttpResponse::json(200, out);
  } catch (const Error& e) {
    return refusal(e, req, r, sha256);
  }
}

}  // namespace

HttpResponse post_locate_chart(ApiContext& ctx, const HttpRequest& req, const PathParams& params) {
  return post_locate(ctx, req, params["sha256"]);
}

}  // namespace colorlab::daemon::routes
