#pragma once
// GET /v1/runs/{id}/export?format=ti3|csv|json (docs/API.md, "Exports"): a run's measurements as a file.
// A read route: served on an HTTP pool thread through ctx.reads().
#include <optional>

#include "colorlab/daemon/api.hpp"
#include "colorlab/http/message.hpp"

namespace colorlab::daemon {

// nullopt when the path is not an export. Throws colorlab::Error (handle_api makes it problem+json).
std::optional<http::HttpResponse> handle_export_api(ApiContext& ctx, const http::HttpRequest& req);

}  // namespace colorlab::daemon
