#pragma once
// The access routes (docs/API.md, "Access"): API keys under /v1/keys (admin) and the control lock
// under /v1/control. handle_api hands every request to handle_access_api after the access check;
// errors are thrown as colorlab::Error and leave as problem+json through handle_api.
#include <optional>

#include "colorlab/daemon/api.hpp"
#include "colorlab/http/message.hpp"

namespace colorlab::daemon {

// nullopt when the path is not /v1/keys…
std::optional<http::HttpResponse> handle_keys_api(ApiContext& ctx, const http::HttpRequest& req);
// nullopt when the path is not /v1/control…
std::optional<http::HttpResponse> handle_control_api(ApiContext& ctx, const http::HttpRequest& req);

inline std::optional<http::HttpResponse> handle_access_api(ApiContext& ctx, const http::HttpRequest& req) {
  if (auto r = handle_keys_api(ctx, req)) return r;
  return handle_control_api(ctx, req);
}

}  // namespace colorlab::daemon
