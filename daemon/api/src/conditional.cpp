#include "colorlab/api/conditional.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <optional>

namespace colorlab::daemon {

std::string_view trim_ows(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

namespace {

std::optional<std::uint64_t> number(std::string_view s) {
  if (s.empty() || s.size() > 19) return std::nullopt;
  std::uint64_t v = 0;
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return v;
}

}  // namespace

ByteRange parse_byte_range(std::string_view header, std::uint64_t size) {
  ByteRange whole;
  std::string_view h = trim_ows(header);
  constexpr std::string_view unit = "bytes=";
  if (h.size() < unit.size()) return whole;
  for (std::size_t i = 0; i < unit.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(h[i])) != unit[i]) return whole;
  }
  h = trim_ows(h.substr(unit.size()));
  if (h.find(',') != std::string_view::npos) return whole;  // several ranges: the whole body (RFC 9110 allows it)
  const auto dash = h.find('-');
  if (dash == std::string_view::npos) return whole;
  const std::string_view a = trim_ows(h.substr(0, dash)), b = trim_ows(h.substr(dash + 1));
  ByteRange r;
  r.kind = ByteRange::Kind::partial;
  if (a.empty()) {  // suffix: the last N bytes
    auto n = number(b);
    if (!n) return whole;
    if (*n == 0 || size == 0) return ByteRange{ByteRange::Kind::unsatisfiable};
    r.first = size - std::min(*n, size);
    r.last = size - 1;
    return r;
  }
  auto first = number(a);
  if (!first) return whole;
  std::optional<std::uint64_t> last;
  if (!b.empty()) {
    last = number(b);
    if (!last || *last < *first) return whole;  // invalid: ignored
  }
  if (*first >= size) return ByteRange{ByteRange::Kind::unsatisfiable};
  r.first = *first;
  r.last = last ? std::min(*last, size - 1) : size - 1;
  return r;
}

bool none_match_hits(std::string_view if_none_match, std::string_view etag) {
  auto opaque = [](std::string_view t) {
    t = trim_ows(t);
    if (t.rfind("W/", 0) == 0) t.remove_prefix(2);
    return t;
  };
  const std::string_view want = opaque(etag);
  std::string_view rest = if_none_match;
  while (!rest.empty()) {
    const auto comma = rest.find(',');
    const std::string_view tag = trim_ows(rest.substr(0, comma));
    if (tag == "*" || (!tag.empty() && opaque(tag) == want)) return true;
    if (comma == std::string_view::npos) break;
    rest.remove_prefix(comma + 1);
  }
  return false;
}

}  // namespace colorlab::daemon
