// GET /v1/runs/{id}/export on central: the bench's own answer (daemon/api/src/routes/export_response.hpp) fed
// from PostgreSQL page by page, so the files are byte for byte what the bench makes of the same rows.
#include "central_routes.hpp"
#include "export_response.hpp"

namespace colorlab::fleet::central_routes {

namespace rx = daemon::run_export;

HttpResponse get_run_export(CentralContext& ctx, const HttpRequest& req, const PathParams& params) {
  const std::string& id = params["id"];
  const rx::Format format = rx::requested_format(req);
  auto pg = ctx.pool.lease();
  const store::RunRecord run = require_run(*pg, id).run;
  CentralRunReader runs(*pg);
  return rx::export_response(
      req, format, run,
      [&pg](const std::string& run_id, const store::MeasurementFilter& filter,
            std::int64_t after, unsigned limit) {
        return central_measurements_page(*pg, run_id, filter, after, limit);
      },
      runs);
}

}  // namespace colorlab::fleet::central_routes
