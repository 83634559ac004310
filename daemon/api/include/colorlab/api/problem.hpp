#pragma once
// The API's one problem+json builder (RFC 9457). Its category (SiLA 2's) follows the error: from
// the colorlab::Error's class when there is one (protocol::problem_from_error), else from the status
// (protocol::category_for_status) — a 503 is `framework`, never `validation`.
#include <string>

#include <nlohmann/json.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/http/message.hpp"

namespace colorlab::daemon {

// `extra`: extension members (RFC 9457 §3.2), e.g. the scope a request needed or who holds the
// control lock, for clients that act on them without parsing prose.
http::HttpResponse problem_response(int status, const std::string& code, const std::string& title,
                                    const std::string& detail, const std::string& hint = {},
                                    const nlohmann::json& extra = nlohmann::json::object());

// A handler's colorlab::Error: status, category and title from its class; `code` is the class's
// name, or the refusal's own code for a store::QueueConflict (queue-reference-unknown, …).
http::HttpResponse error_response(const Error& e, const std::string& instance);

}  // namespace colorlab::daemon
