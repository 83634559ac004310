#include "colorlab/api/conditional.hpp"

#include <nlohmann/json.hpp>

#include "colorlab/campaigns/frame_keeper.hpp"
#include "colorlab/core/error.hpp"
#include "blob_headers.hpp"
#include "colorlab/daemon/blob_service.hpp"
#include "colorlab/api/problem.hpp"
#include "colorlab/protocol/api.hpp"
#include "colorlab/store/blob_index.hpp"
#include "handlers.hpp"

// The blob routes of the v1 API (docs/API.md, "Blobs"): a stored frame by its SHA-256 with ETag,
// If-None-Match, a single Range and the array's dtype/shape/CFA in headers; its PNG preview; a
// run's blobs; the start-up check's report; retention on request.
namespace colorlab::daemon::routes {

namespace fs = std::filesystem;
using http::HttpRequest;
using http::HttpResponse;
using nlohmann::json;

namespace {

// Served on the HTTP pool: the calling thread's own read connection, never the writer.
store::Store& reads(ApiContext& ctx) { return ctx.reads(); }

BlobService& service(ApiContext& ctx) {
  if (!ctx.blobs) throw Error(ErrorClass::unsupported, "this daemon keeps no blob store");
  return *ctx.blobs;
}

store::BlobRecord require_blob(ApiContext& ctx, const std::string& sha256) {
  if (!store::BlobStore::is_sha256(sha256)) {
    throw Error(ErrorClass::not_found, "no blob named '" + sha256.substr(0, 80) + "'",
                "a blob is named by the 64 lower-case hex digits of its SHA-256 (GET /v1/runs/{id}/blobs lists a run's)");
  }
  auto row = store::BlobIndex(reads(ctx)).blob(sha256);
  if (!row) throw Error(ErrorClass::not_found, "no blob " + sha256, "GET /v1/runs/{id}/blobs lists a run's blobs");
  return *row;
}

HttpResponse serve_blob(ApiContext& ctx, const HttpRequest& req, const std::string& sha256) {
  const store::BlobRecord blob = require_blob(ctx, sha256);
  const fs::path path = service(ctx).files().path_of(sha256);
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  if (ec) {
    throw Error(ErrorClass::not_found, "the file of blob " + sha256 + " is missing from the blob store",
                "GET /v1/blobs/check lists what the store lacks");
  }
  HttpResponse r;
  const BlobSpan span = answer_blob(r, req, blob, size);
  if (span.body_needed) r.file = http::FileSpan{path, span.offset, span.length};
  return r;
}

HttpResponse serve_preview(ApiContext& ctx, const HttpRequest& req, const std::string& sha256) {
  const store::BlobRecord blob = require_blob(ctx, sha256);
  const fs::path png = service(ctx).preview_path(reads(ctx), blob);
  std::error_code ec;
  const auto size = fs::file_size(png, ec);
  if (ec) throw Error(ErrorClass::not_found, "the preview of blob " + sha256 + " is gone");
  // Weak: the same frame's preview may be rendered anew by a later version, with other bytes.
  const std::string etag = "W/\"preview-" + sha256 + "\"";
  HttpResponse r;
  r.content_type = "image/png";
  r.headers["ETag"] = etag;
  r.headers["Cache-Control"] = "public, max-age=86400";
  if (auto inm = req.header("if-none-match"); inm && none_match_hits(*inm, etag)) {
    r.status = 304;
    return r;
  }
  r.file = http::FileSpan{png, 0, size};
  return r;
}

json blob_links(const std::string& sha256) {
  const std::string self = std::string(protocol::kPrefix) + "/blobs/" + sha256;
  return json{{"self", self}, {"preview", self + "/preview.png"}};
}

HttpResponse run_blobs(ApiContext& ctx, const std::string& run_id) {
  store::Store& db = reads(ctx);
  if (!db.run(run_id)) throw Error(ErrorClass::not_found, "no run with id '" + run_id + "'");
  json items = json::array();
  for (const auto& b : store::BlobIndex(db).of_run(run_id)) {
    items.push_back({{"name", b.name},
                     {"sha256", b.blob.sha256},
                     {"kind", b.kind},
                     {"step", b.step},
                     {"media_type", b.blob.media_type},
                     {"size", b.blob.size},
                     {"meta", b.blob.meta},
                     {"created_at", b.created_at},
                     {"links", blob_links(b.blob.sha256)}});
  }
  return HttpResponse::json(200, {{"run_id", run_id}, {"items", items}});
}

HttpResponse retention(ApiContext& ctx, const HttpRequest& req) {
  bool dry_run = false;
  if (auto it = req.query.find("dry_run"); it != req.query.end()) {
    if (it->second != "true" && it->second != "false" && it->second != "1" && it->second != "0") {
      throw Error(ErrorClass::bad_parameter, "dry_run must be true or false");
    }
    dry_run = it->second == "true" || it->second == "1";
  }
  return HttpResponse::json(200, service(ctx).apply_retention(dry_run));
}

}  // namespace

HttpResponse get_run_blobs(ApiContext& ctx, const HttpRequest&, const PathParams& params) {
  return run_blobs(ctx, params["id"]);
}

HttpResponse get_blob(ApiContext& ctx, const HttpRequest& req, const PathParams& params) {
  return serve_blob(ctx, req, params["sha256"]);
}

HttpResponse get_blob_preview(ApiContext& ctx, const HttpRequest& req, const PathParams& params) {
  return serve_preview(ctx, req, params["sha256"]);
}

HttpResponse get_blob_check(ApiContext& ctx, const HttpRequest&, const PathParams&) {
  return HttpResponse::json(200, service(ctx).check_report());
}

HttpResponse post_blob_retention(ApiContext& ctx, const HttpRequest& req, const PathParams&) { return retention(ctx, req); }

}  // namespace colorlab::daemon::routes
