// GET /v1/runs/{id}/export?format=ti3|csv|json (docs/API.md, "Exports"): a run's measurements as a file.
// A read route: served on an HTTP pool thread through ctx.reads(). The answer itself is export_response.cpp,
// which central serves too.
#include "colorlab/core/error.hpp"
#include "colorlab/daemon/store_run_reader.hpp"
#include "export_response.hpp"
#include "handlers.hpp"

namespace colorlab::daemon::routes {

namespace rx = run_export;

HttpResponse get_run_export(ApiContext& ctx, const HttpRequest& req, const PathParams& params) {
  const std::string& id = params["id"];
  const rx::Format format = rx::requested_format(req);
  store::Store& db = ctx.reads();
  auto run = db.run(id);
  if (!run) throw Error(ErrorClass::not_found, "no run with id '" + id + "'");
  StoreRunReader runs(db);
  return rx::export_response(
      req, format, *run,
      [&db](const std::string& run_id, const store::MeasurementFilter& filter,
            std::int64_t after, unsigned limit) {
        return db.measurements_page(run_id, filter, after, limit);
      },
      runs);
}

}  // namespace colorlab::daemon::routes
