#pragma once
// What a GET and a HEAD of a blob share before the body — identity, type, caching, the conditional and the
// range — on the bench (blob_routes.cpp, the body from a file) and on central (fleet/central/central_blob.cpp,
// the body relayed from the bucket). The bytes of a name never change, so a client may keep them for good; an
// array blob carries its dtype, shape and CFA as headers.
#include <cstdint>
#include <string>

#include "colorlab/http/message.hpp"
#include "colorlab/store/blob_index.hpp"

namespace colorlab::daemon {

void describe_blob(http::HttpResponse& r, const store::BlobRecord& blob, const std::string& etag);

// The answer to a GET or HEAD of a blob of `size` bytes, before its body: `r` described, then finished as a 304
// (If-None-Match) or a 416 problem (body_needed false), or 200/206 with its Content-Range and the span of bytes
// the body is (If-Range with another tag asks for the whole blob).
struct BlobSpan {
  bool body_needed = false;
  bool partial = false;
  std::uint64_t offset = 0;
  std::uint64_t length = 0;
};
BlobSpan answer_blob(http::HttpResponse& r, const http::HttpRequest& req, const store::BlobRecord& blob,
                     std::uint64_t size);

}  // namespace colorlab::daemon
