#pragma once
// The blob routes of the v1 API (docs/API.md, "Blobs"): a stored frame by its SHA-256 with ETag,
// If-None-Match, a single Range and the array's dtype/shape/CFA in headers; its PNG preview; a
// run's blobs; the start-up check's report; retention on request.
#include <cstdint>
#include <optional>
#include <string_view>

#include "colorlab/daemon/api.hpp"
#include "colorlab/http/message.hpp"

namespace colorlab::daemon {

// nullopt when the path is not a blob route. Throws colorlab::Error (handle_api makes it problem+json).
std::optional<http::HttpResponse> handle_blob_api(ApiContext& ctx, const http::HttpRequest& req);

// RFC 9110 §14: a `Range` header against a representation of `size` bytes. One range of bytes is
// served (partial); anything else this server does not serve partially — several ranges, another
// unit, a malformed header — is answered whole, as the RFC allows; a range that starts beyond the
// end is unsatisfiable (416).
struct ByteRange {
  enum class Kind { whole, partial, unsatisfiable } kind = Kind::whole;
  std::uint64_t first = 0;
  std::uint64_t last = 0;  // inclusive
};
ByteRange parse_byte_range(std::string_view header, std::uint64_t size);

// If-None-Match (weak comparison, RFC 9110 §13.1.2) against a strong entity tag such as "\"abc\"".
bool none_match_hits(std::string_view if_none_match, std::string_view etag);

}  // namespace colorlab::daemon
