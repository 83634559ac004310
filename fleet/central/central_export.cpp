// GET /v1/runs/{id}/export on central: the bench's conversions (daemon/api/src/routes/run_export.hpp) fed from
// PostgreSQL page by page, so the files are byte for byte what the bench makes of the same rows. The choice of
// format and of which .ti3 a run makes follows export_routes.cpp, whose helpers read the bench's SQLite store.
#include "central_routes.hpp"
#include "colorlab/api/problem.hpp"
#include "colorlab/core/error.hpp"
#include "run_export.hpp"

namespace colorlab::fleet::central_routes {

namespace rx = daemon::run_export;

namespace {

constexpr unsigned kPage = 1000;

template <typename Each>
void for_each_measurement(Pg& pg, const std::string& run_id, const store::MeasurementFilter& filter, Each&& each) {
  std::int64_t after = 0;
  for (;;) {
    auto page = central_measurements_page(pg, run_id, filter, after, kPage);
    for (const auto& m : page.items) each(m);
    if (!page.next_after) return;
    after = *page.next_after;
  }
}

std::vector<store::MeasurementRecord> all_measurements(Pg& pg, const std::string& run_id,
                                                       const store::MeasurementFilter& filter) {
  std::vector<store::MeasurementRecord> out;
  for_each_measurement(pg, run_id, filter, [&](const store::MeasurementRecord& m) { out.push_back(m); });
  return out;
}

rx::Format requested_format(const HttpRequest& req) {
  if (auto it = req.query.find("format"); it != req.query.end()) return rx::parse_format(it->second);
  const auto accept = req.header("accept");
  if (!accept || accept->empty()) return rx::Format::json;
  if (auto f = rx::format_for_accept(*accept)) return *f;
  throw Error(ErrorClass::bad_parameter, "Accept: " + *accept + " names no export format",
              "give format=ti3, csv or json, or Accept: text/x-cgats, text/csv or application/json");
}

std::string ti3_body(Pg& pg, const store::RunRecord& run, const HttpRequest& req, std::string& part) {
  auto first = central_measurements_page(pg, run.id, {.quantity = "camera_rgb"}, 0, 1);
  if (!first.items.empty()) {
    std::string format = rx::default_camera_format(run, first.items.front());
    if (auto it = req.query.find("camera_format"); it != req.query.end()) format = it->second;
    const std::string reference_run = run.params.is_object() ? run.params.value("reference_run", std::string()) : "";
    if (reference_run.empty())
      throw Error(ErrorClass::unsupported, "run " + run.id + " has camera values but names no reference_run to pair them with",
                  "export it as csv or json");
    CentralRunReader runs(pg);
    const auto reference = campaigns::chart_reference(runs, reference_run);
    part = format;
    return rx::camera_ti3(run, all_measurements(pg, run.id, {.step_prefix = "patch/" + format + "/", .quantity = "camera_rgb"}),
                          reference, format);
  }
  auto patches = all_measurements(pg, run.id, {.step_prefix = "patch/", .quantity = "reflectance_spectrum"});
  if (patches.empty())
    throw Error(ErrorClass::unsupported,
                "run " + run.id + " (" + run.campaign + ") has no patch readings: a .ti3 pairs patches' device values with "
                "their colour, as a chart-read or characterize-camera run records them",
                "export it as csv or json, which hold every measurement as stored");
  return rx::reference_ti3(run, patches);
}

}  // namespace

HttpResponse get_run_export(CentralContext& ctx, const HttpRequest& req, const PathParams& params) {
  const std::string& id = params["id"];
  const rx::Format format = requested_format(req);
  auto pg = ctx.pool.lease();
  const store::RunRecord run = require_run(*pg, id).run;
  HttpResponse r;
  std::string part;
  switch (format) {
    case rx::Format::csv: {
      rx::CsvBody body;
      for_each_measurement(*pg, id, {}, [&](const store::MeasurementRecord& m) { body.add(m); });
      r.body = body.take();
      break;
    }
    case rx::Format::json: {
      rx::JsonBody body(run);
      for_each_measurement(*pg, id, {}, [&](const store::MeasurementRecord& m) { body.add(m); });
      r.body = body.take();
      break;
    }
    case rx::Format::ti3:
      try {
        r.body = ti3_body(*pg, run, req, part);
      } catch (const Error& e) {
        if (e.cls() != ErrorClass::unsupported) throw;
        return daemon::problem_response(422, "not-exportable", "Not exportable as ti3", e.info().message, e.hint(),
                                        {{"instance", req.path}, {"formats", {"csv", "json"}}});
      }
      break;
  }
  r.status = 200;
  r.content_type = rx::media_type(format);
  r.headers["Content-Disposition"] = "attachment; filename=\"" + rx::file_name(run, format, part) + "\"";
  r.headers["Vary"] = "Accept";
  return r;
}

}  // namespace colorlab::fleet::central_routes
