#pragma once
// The handlers of colorlab-central's routes (central_api.cpp routes to them). Each leases one PostgreSQL
// connection for its request; errors leave as colorlab::Error and become problem+json in handle_central.
#include "colorlab/api/route.hpp"
#include "colorlab/fleet/central_api.hpp"

namespace colorlab::fleet::central_routes {

using http::HttpRequest;
using http::HttpResponse;
using daemon::PathParams;

HttpResponse get_root(CentralContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_benches(CentralContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_runs(CentralContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_run(CentralContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_run_measurements(CentralContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_run_blobs(CentralContext& ctx, const HttpRequest& req, const PathParams& params);
// central_blob.cpp: a blob from the bucket, with ETag, If-None-Match and one Range.
HttpResponse get_blob(CentralContext& ctx, const HttpRequest& req, const PathParams& params);
// central_export.cpp: CSV, JSON and .ti3 by the bench's own conversions.
HttpResponse get_run_export(CentralContext& ctx, const HttpRequest& req, const PathParams& params);

// A run central holds, or Error{not_found} saying it may not have shipped yet.
CentralRun require_run(Pg& pg, const std::string& id);

}  // namespace colorlab::fleet::central_routes
