#pragma once
// Every handler the route table (../route_table.cpp) names, by the file that holds it. Each has the
// one signature RouteHandler (route.hpp): the route's path parameters come in `params`; errors are
// thrown as colorlab::Error and leave as problem+json through the router.
#include "colorlab/api/context.hpp"
#include "colorlab/api/route.hpp"
#include "colorlab/http/message.hpp"

namespace colorlab::daemon::routes {

using http::HttpRequest;
using http::HttpResponse;

// lab_routes.cpp: the daemon and the lab as they are now.
HttpResponse get_root(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_instruments(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_ports(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_lab_cabinet(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_lab_lenses(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_campaigns(ApiContext& ctx, const HttpRequest& req, const PathParams& params);

// ship_routes.cpp: colorlab-ship's lag and last error, read from the bench's own files.
HttpResponse get_shipping(ApiContext& ctx, const HttpRequest& req, const PathParams& params);

// event_routes.cpp: the event log, paged and live.
HttpResponse get_events(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_event_stream(ApiContext& ctx, const HttpRequest& req, const PathParams& params);

// execution_routes.cpp
HttpResponse post_execution(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_executions(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_execution(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse post_execution_pause(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse post_execution_resume(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse post_execution_abort(ApiContext& ctx, const HttpRequest& req, const PathParams& params);

// operator_routes.cpp: operator requests.
HttpResponse get_requests(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_request(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse post_request_answer(ApiContext& ctx, const HttpRequest& req, const PathParams& params);

// queue_routes.cpp: the night's queue.
HttpResponse get_queue(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse post_queue(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse post_queue_start(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse post_queue_stop(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_queue_item(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse delete_queue_item(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse post_queue_move(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_queue_group(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_queue_group_report(ApiContext& ctx, const HttpRequest& req, const PathParams& params);

// key_routes.cpp: API keys (admin).
HttpResponse get_keys(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse post_key(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_key(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse delete_key(ApiContext& ctx, const HttpRequest& req, const PathParams& params);

// control_routes.cpp: the control lock.
HttpResponse get_control(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse post_control_acquire(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse post_control_release(ApiContext& ctx, const HttpRequest& req, const PathParams& params);

// run_routes.cpp: stored runs.
HttpResponse get_runs(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_run(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_run_script(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_run_measurements(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_run_report(ApiContext& ctx, const HttpRequest& req, const PathParams& params);

// export_routes.cpp
HttpResponse get_run_export(ApiContext& ctx, const HttpRequest& req, const PathParams& params);

// blob_routes.cpp: the image store.
HttpResponse get_run_blobs(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_blob(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_blob_preview(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse get_blob_check(ApiContext& ctx, const HttpRequest& req, const PathParams& params);
HttpResponse post_blob_retention(ApiContext& ctx, const HttpRequest& req, const PathParams& params);

// locate_routes.cpp
HttpResponse post_locate_chart(ApiContext& ctx, const HttpRequest& req, const PathParams& params);

// verify_routes.cpp: a rendering's verification stored as a run (issue 23).
HttpResponse post_verification(ApiContext& ctx, const HttpRequest& req, const PathParams& params);

}  // namespace colorlab::daemon::routes
