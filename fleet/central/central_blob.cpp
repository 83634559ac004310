// GET /v1/blobs/{sha256} on central: the object sha256/<hex> from the bucket, with the bench's headers and rules
// (daemon/api/src/routes/blob_routes.cpp): a strong ETag that is the name, If-None-Match answered from the
// catalog without touching the bucket, one Range passed on to the store as a ranged GET, If-Range, 416.

#include "central_routes.hpp"
#include "colorlab/api/conditional.hpp"
#include "colorlab/api/problem.hpp"
#include "colorlab/core/error.hpp"
#include "blob_headers.hpp"
#include "colorlab/store/blob_store.hpp"

namespace colorlab::fleet::central_routes {

HttpResponse get_blob(CentralContext& ctx, const HttpRequest& req, const PathParams& params) {
  const std::string& sha256 = params["sha256"];
  if (!store::BlobStore::is_sha256(sha256)) {
    throw Error(ErrorClass::not_found, "no blob named '" + sha256.substr(0, 80) + "'",
                "a blob is named by the 64 lower-case hex digits of its SHA-256 (GET /v1/runs/{id}/blobs lists a run's)");
  }
  std::optional<store::BlobRecord> blob;
  {
    auto pg = ctx.pool.lease();  // not held while the bytes come from the bucket
    blob = central_blob(*pg, sha256);
  }
  if (!blob) throw Error(ErrorClass::not_found, "central holds no blob " + sha256, "GET /v1/runs/{id}/blobs lists a run's blobs");
  const std::uint64_t size = blob->size;
  const std::string etag = "\"" + sha256 + "\"";
  HttpResponse r;
  r.content_type = blob->media_type;
  daemon::describe_blob(r, *blob, etag);
  if (auto inm = req.header("if-none-match"); inm && daemon::none_match_hits(*inm, etag)) {
    r.status = 304;
    return r;
  }
  daemon::ByteRange range;
  if (auto h = req.header("range")) {
    range = daemon::parse_byte_range(*h, size);
    if (auto ir = req.header("if-range"); ir && daemon::trim_ows(*ir) != etag) range.kind = daemon::ByteRange::Kind::whole;
  }
  if (range.kind == daemon::ByteRange::Kind::unsatisfiable) {
    auto p = daemon::problem_response(416, "range-not-satisfiable", "Range not satisfiable",
                                      "blob " + sha256 + " has " + std::to_string(size) +
                                          " bytes; the range asked for starts beyond them");
    daemon::describe_blob(p, *blob, etag);
    p.headers["Content-Range"] = "bytes */" + std::to_string(size);
    return p;
  }
  const std::string key = "sha256/" + sha256;
  // A HEAD fetches the bytes too: the server sets Content-Length from the body it then drops.
  if (range.kind == daemon::ByteRange::Kind::partial) {
    r.status = 206;
    r.headers["Content-Range"] =
        "bytes " + std::to_string(range.first) + "-" + std::to_string(range.last) + "/" + std::to_string(size);
    r.body = ctx.s3.get_part(key, std::pair(range.first, range.last));
    if (r.body.size() != range.last - range.first + 1) {
      throw Error(ErrorClass::io_error, "the bucket answered " + std::to_string(r.body.size()) + " bytes of " + key +
                                            " for a range of " + std::to_string(range.last - range.first + 1));
    }
    return r;
  }
  r.status = 200;
  r.body = ctx.s3.get_part(key, std::nullopt);
  // The whole object is checked against its name: central never hands out bytes the bucket let rot.
  if (r.body.size() != size || sha256_hex(r.body) != sha256) {
    throw Error(ErrorClass::io_error, "the bucket's object " + key + " does not hash to its name",
                "re-ship it from a bench that holds it (colorlab-ship uploads a missing or damaged object again)");
  }
  return r;
}

}  // namespace colorlab::fleet::central_routes
