#pragma once
// POST /v1/blobs/{sha256}/locate-chart: the chart located (and every patch sampled) in a photograph already in the
// image store, automatically or from the operator's four corners (issue 14). It changes nothing stored, so it needs
// only the read scope and runs on the HTTP pool like the other stored-data routes.
#include <optional>
#include <string>

#include "colorlab/daemon/api.hpp"
#include "colorlab/http/message.hpp"

namespace colorlab::daemon {

// Whether `path` is a blob's locate-chart route (whatever the method): for the access check and the pool.
bool is_locate_chart_path(const std::string& path);

// nullopt when the path is not the route's. Throws colorlab::Error for an unknown blob (404).
std::optional<http::HttpResponse> handle_locate_api(ApiContext& ctx, const http::HttpRequest& req);

}  // namespace colorlab::daemon
