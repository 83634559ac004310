#pragma once
// GET /v1/runs/{id}/export's answer, whichever store holds the run: the bench's SQLite (export_routes.cpp) and
// central's PostgreSQL (fleet/central/central_export.cpp) hand over pages of the run's measurements and a
// RunReader, so both make the same files, choose the same .ti3 and refuse the same way.
#include <cstdint>
#include <functional>
#include <string>

#include "colorlab/campaigns/run_reader.hpp"
#include "colorlab/http/message.hpp"
#include "colorlab/store/store.hpp"
#include "run_export.hpp"

namespace colorlab::daemon::run_export {

// One keyset page of a run's measurements: (run id, filter, after seq, at most) → page.
using MeasurementPages = std::function<store::MeasurementPage(const std::string& run_id, const store::MeasurementFilter& filter,
                                                              std::int64_t after, unsigned limit)>;

// The format asked for by ?format=, else by Accept (JSON when there is none); Error(bad_parameter) otherwise.
Format requested_format(const http::HttpRequest& req);

// The file in `format` of `run`'s measurements; a run no .ti3 can be made of answers 422 not-exportable.
// `runs` finds a camera run's chart-read reference.
http::HttpResponse export_response(const http::HttpRequest& req, Format format, const store::RunRecord& run,
                                   const MeasurementPages& pages, campaigns::RunReader& runs);

}  // namespace colorlab::daemon::run_export
