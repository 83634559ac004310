#include "blob_headers.hpp"

#include <nlohmann/json.hpp>

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

}  // namespace colorlab::daemon
