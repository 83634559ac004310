#include "blob_headers.hpp"

#include <nlohmann/json.hpp>

#include "colorlab/api/conditional.hpp"
#include "colorlab/api/problem.hpp"
#include "colorlab/campaigns/frame_keeper.hpp"

namespace colorlab::daemon {

using nlohmann::json;

namespace {

std::string join_shape(const json& shape) {
  std::string out;
  for (const auto& d : shape) out += (out.empty() ? "" : ",") + std::to_string(d.get<long long>());
  return out;
}

}  // namespace

void describe_blob(http::HttpResponse& r, const store::BlobRecord& blob, const std::string& etag) {
  r.headers["ETag"] = etag;
  r.headers["Accept-Ranges"] = "bytes";
  r.headers["Cache-Control"] = "public, max-age=31536000, immutable";
  if (blob.media_type == campaigns::kArrayMediaType) {
    const json& m = blob.meta;
    if (m.contains("dtype") && m["dtype"].is_string()) r.headers["X-Colorlab-Dtype"] = m["dtype"].get<std::string>();
    if (m.contains("shape") && m["shape"].is_array()) r.headers["X-Colorlab-Shape"] = join_shape(m["shape"]);
    if (m.contains("cfa") && m["cfa"].is_string()) r.headers["X-Colorlab-Cfa"] = m["cfa"].get<std::string>();
  }
}

BlobSpan answer_blob(http::HttpResponse& r, const http::HttpRequest& req, const store::BlobRecord& blob,
                     std::uint64_t size) {
  const std::string etag = "\"" + blob.sha256 + "\"";
  r.content_type = blob.media_type;
  describe_blob(r, blob, etag);
  if (auto inm = req.header("if-none-match"); inm && none_match_hits(*inm, etag)) {
    r.status = 304;
    return {};
  }
  ByteRange range;
  if (auto h = req.header("range")) {
    range = parse_byte_range(*h, size);
    // If-Range compares strongly: a weak or another tag (or a date: ours never changes, yet we
    // have no Last-Modified to compare with) means "send it whole".
    if (auto ir = req.header("if-range"); ir && trim_ows(*ir) != etag) range.kind = ByteRange::Kind::whole;
  }
  if (range.kind == ByteRange::Kind::unsatisfiable) {
    r = problem_response(416, "range-not-satisfiable", "Range not satisfiable",
                         "blob " + blob.sha256 + " has " + std::to_string(size) +
                             " bytes; the range asked for starts beyond them");
    describe_blob(r, blob, etag);
    r.headers["Content-Range"] = "bytes */" + std::to_string(size);
    return {};
  }
  if (range.kind == ByteRange::Kind::partial) {
    r.status = 206;
    r.headers["Content-Range"] =
        "bytes " + std::to_string(range.first) + "-" + std::to_string(range.last) + "/" + std::to_string(size);
    return {true, true, range.first, range.last - range.first + 1};
  }
  r.status = 200;
  return {true, false, 0, size};
}

}  // namespace colorlab::daemon
