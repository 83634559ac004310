#pragma once
// Conditional and partial requests (RFC 9110 §13, §14), shared by the blob routes, the reports and
// the console's files.
#include <cstdint>
#include <string_view>

namespace colorlab::daemon {

// RFC 9110 §14: a `Range` header against a representation of `size` bytes. One range of bytes is
// served (partial); anything else this server does not serve partially — several ranges, another
// unit, a malformed header — is answered whole, as the RFC allows; a range that starts beyond the
// end is unsatisfiable (416).
struct ByteRange {
  enum class Kind {
    whole,
    partial,
    unsatisfiable
  } kind = Kind::whole;
  std::uint64_t first = 0;
  std::uint64_t last = 0;  // inclusive
};
ByteRange parse_byte_range(std::string_view header, std::uint64_t size);

// If-None-Match (weak comparison, RFC 9110 §13.1.2) against a strong entity tag such as "\"abc\"".
bool none_match_hits(std::string_view if_none_match, std::string_view etag);

// Optional whitespace (spaces, tabs) off both ends.
std::string_view trim_ows(std::string_view s);

}  // namespace colorlab::daemon
