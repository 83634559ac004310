// GET /v1/blobs/{sha256} on central: the object sha256/<hex> from the bucket, with the bench's headers and rules
// (daemon/api/src/routes/blob_routes.cpp): a strong ETag that is the name, If-None-Match answered from the
// catalog without touching the bucket, one Range passed on to the store as a ranged GET, If-Range, 416. The body
// is relayed as the store sends it (S3Download), with the catalog's length as its Content-Length.

#include "central_routes.hpp"
#include "colorlab/core/error.hpp"
#include "blob_headers.hpp"
#include "colorlab/store/blob_store.hpp"

#include <memory>

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
  const std::string key = blob_key(sha256);
  HttpResponse r;
  const daemon::BlobSpan span = daemon::answer_blob(r, req, *blob, blob->size);
  if (!span.body_needed) return r;
  const bool partial = span.partial;
  const std::uint64_t length = span.length;
  // The length is the catalog's (the server sends the stream unchunked with it); a HEAD is answered without
  // touching the bucket.
  r.headers["Content-Length"] = std::to_string(length);
  if (req.method == "HEAD") return r;
  // Opened here, so a missing object or a refusing store is still a problem+json; the bytes follow as they come
  // from the store, about one S3Download::kPiece at a time, never the whole object or range in memory.
  std::optional<std::pair<std::uint64_t, std::uint64_t>> bytes;
  if (partial) bytes = std::pair(span.offset, span.offset + length - 1);
  auto download = std::make_shared<S3Download>(ctx.s3, key, bytes);
  r.stream = [download, length, partial, key, sha256](http::StreamWriter& out) -> boost::asio::awaitable<void> {
    // One piece is held back until the end: a whole object that does not hash to its name, or a body of the
    // wrong length, ends the connection short of its Content-Length, so the client never takes it as complete.
    // Central never hands out bytes the bucket let rot.
    std::string held;
    for (;;) {
      std::string piece = download->next();
      if (piece.empty()) break;
      if (download->delivered() > length) break;
      if (!held.empty() && !co_await out.send(held)) co_return;
      held = std::move(piece);
    }
    if (download->delivered() != length) {
      throw Error(ErrorClass::io_error, "the bucket answered " + std::to_string(download->delivered()) +
                                            " bytes or more of " + key + " for " + std::to_string(length));
    }
    if (!partial && download->sha256_hex() != sha256) {
      throw Error(ErrorClass::io_error, "the bucket's object " + key + " does not hash to its name",
                  "re-ship it from a bench that holds it (colorlab-ship uploads a missing or damaged object again)");
    }
    co_await out.send(held);
  };
  return r;
}

}  // namespace colorlab::fleet::central_routes
