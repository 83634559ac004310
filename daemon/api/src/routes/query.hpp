#pragma once
// Query parameters the list routes share.
#include <cstdint>
#include <stdexcept>
#include <string>

#include "colorlab/core/error.hpp"
#include "colorlab/http/message.hpp"
#include "colorlab/protocol/api.hpp"

namespace colorlab::daemon::routes {

// ?limit=: a page's size, 1..`most`; `fallback` without it. Error{bad_parameter} otherwise.
inline unsigned page_limit(const http::HttpRequest& req, unsigned fallback = protocol::kDefaultPageLimit,
                           unsigned most = protocol::kMaxPageLimit) {
  auto it = req.query.find("limit");
  if (it == req.query.end()) return fallback;
  try {
    std::size_t used = 0;
    long v = std::stol(it->second, &used);
    if (used != it->second.size() || v < 1 || v > static_cast<long>(most)) throw std::out_of_range("limit");
    return static_cast<unsigned>(v);
  } catch (const std::exception&) {
    throw Error(ErrorClass::bad_parameter, "limit must be an integer from 1 to " + std::to_string(most));
  }
}

// ?`name`=: a non-negative whole number (a sequence number or a page's cursor); 0 without it.
// Error{bad_parameter} with `refusal` otherwise.
inline std::int64_t non_negative_query(const http::HttpRequest& req, const std::string& name,
                                       const std::string& refusal) {
  auto it = req.query.find(name);
  if (it == req.query.end()) return 0;
  try {
    std::size_t used = 0;
    const long long v = std::stoll(it->second, &used);
    if (used != it->second.size() || v < 0) throw std::invalid_argument(name);
    return v;
  } catch (const std::exception&) {
    throw Error(ErrorClass::bad_parameter, refusal);
  }
}

}  // namespace colorlab::daemon::routes
