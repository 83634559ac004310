#pragma once
// The night's queue routes under /v1/queue (docs/API.md). handle_api hands every request to this
// first; errors are thrown as colorlab::Error and leave as problem+json through handle_api.
#include <optional>

#include "colorlab/daemon/api.hpp"
#include "colorlab/http/message.hpp"

namespace colorlab::daemon {

// nullopt when the path is not the queue's.
std::optional<http::HttpResponse> handle_queue_api(ApiContext& ctx, const http::HttpRequest& req);

}  // namespace colorlab::daemon
