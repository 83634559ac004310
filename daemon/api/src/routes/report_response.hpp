#pragma once
// The answer for a report the ReportService makes, shared by a run's report and a study's (a queued
// sequence's group): 202 with Retry-After until it is made — for a browser a page that reloads itself, so
// following the link just works — 500 with the child's words when it failed, the file with an ETag once made.
#include <string>
#include <vector>

#include "colorlab/daemon/report_service.hpp"
#include "colorlab/http/message.hpp"

namespace colorlab::daemon {

// `key` names the report's file; `what` says in the waiting page what is being made ("run 0190…").
http::HttpResponse report_response(ReportService* reports, const http::HttpRequest& req, const std::string& key,
                                   const std::vector<std::string>& run_ids, const std::string& what);

}  // namespace colorlab::daemon
