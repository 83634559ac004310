#pragma once
// Strict number parsing shared by the file readers: a cell is a number or an error, never a silent 0.
#include <charconv>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>

#include "colorlab/core/error.hpp"

namespace colorlab::analysis::detail {

inline std::optional<double> to_double(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return std::nullopt;
  double v = 0;
  auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || ptr != s.data() + s.size()) return std::nullopt;
  return v;
}

[[noreturn]] inline void fail(const std::string& what, const std::string& hint = {}) {
  throw Error(ErrorClass::bad_data, what, hint);
}

}  // namespace colorlab::analysis::detail
