#pragma once
// A problem+json response with extension members (RFC 9457 §3.2), e.g. the scope a request
// needed or who holds the control lock, for clients that act on them without parsing prose.
#include <string>

#include <nlohmann/json.hpp>

#include "colorlab/http/message.hpp"
#include "colorlab/protocol/api.hpp"
#include "colorlab/protocol/problem.hpp"

namespace colorlab::daemon {

inline http::HttpResponse problem_response(int status, const std::string& code, const std::string& title,
                                           const std::string& detail, const std::string& hint,
                                           const nlohmann::json& extra = nlohmann::json::object()) {
  protocol::Problem p;
  p.status = status;
  p.code = code;
  p.title = title;
  p.detail = detail;
  p.hint = hint;
  p.category = protocol::ProblemCategory::validation;
  nlohmann::json body = p.to_json();
  body.update(extra);
  http::HttpResponse r;
  r.status = status;
  r.content_type = std::string(protocol::kContentProblem);
  r.body = body.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  return r;
}

}  // namespace colorlab::daemon
