// GET /v1/runs/{id}/export?format=ti3|csv|json (docs/API.md, "Exports"): a run's measurements as a file.
// A read route: served on an HTTP pool thread through ctx.reads().
#include "colorlab/campaigns/run_reader.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/protocol/api.hpp"
#include "colorlab/api/problem.hpp"
#include "handlers.hpp"
#include "run_export.hpp"
#include "colorlab/daemon/store_run_reader.hpp"

namespace colorlab::daemon::routes {

namespace rx = run_export;

namespace {

// Keyset pages keep one page of rows in memory beside the body being built (a run holds at most ~10^5).
constexpr unsigned kPage = 1000;

template <typename Each>
void for_each_measurement(store::Store& db, const std::string& run_id, const store::MeasurementFilter& filter, Each&& each) {
  std::int64_t after = 0;
  for (;;) {
    auto page = db.measurements_page(run_id, filter, after, kPage);
    for (const auto& m : page.items) each(m);
    if (!page.next_after) return;
    after = *page.next_after;
  }
}

std::vector<store::MeasurementRecord> all_measurements(store::Store& db, const std::string& run_id, const store::MeasurementFilter& filter) {
  std::vector<store::MeasurementRecord> out;
  for_each_measurement(db, run_id, filter, [&](const store::MeasurementRecord& m) { out.push_back(m); });
  return out;
}

std::optional<store::MeasurementRecord> first_measurement(store::Store& db, const std::string& run_id, const store::MeasurementFilter& filter) {
  auto page = db.measurements_page(run_id, filter, 0, 1);
  if (page.items.empty()) return std::nullopt;
  return page.items.front();
}

rx::Format requested_format(const HttpRequest& req) {
  if (auto it = req.query.find("format"); it != req.query.end()) return rx::parse_format(it->second);
  const auto accept = req.header("accept");
  if (!accept || accept->empty()) return rx::Format::json;
  if (auto f = rx::format_for_accept(*accept)) return *f;
  throw Error(ErrorClass::bad_parameter, "Accept: " + *accept + " names no export format",
              "give format=ti3, csv or json, or Accept: text/x-cgats, text/csv or application/json");
}

// Which .ti3 a run makes: a camera's patch values paired with the chart-read it was fitted against, or the
// chart-read's own readings. `part` names the camera format in the file name.
std::string ti3_body(store::Store& db, const store::RunRecord& run, const HttpRequest& req, std::string& part) {
  if (auto first = first_measurement(db, run.id, {.quantity = "camera_rgb"})) {
    std::string format = rx::default_camera_format(run, *first);
    if (auto it = req.query.find("camera_format"); it != req.query.end()) format = it->second;
    const std::string reference_run = run.params.is_object() ? run.params.value("reference_run", std::string()) : "";
    if (reference_run.empty())
      throw Error(ErrorClass::unsupported, "run " + run.id + " has camera values but names no reference_run to pair them with",
                  "export it as csv or json");
    StoreRunReader runs(db);
    const auto reference = campaigns::chart_reference(runs, reference_run);
    part = format;
    return rx::camera_ti3(run, all_measurements(db, run.id, {.step_prefix = "patch/" + format + "/", .quantity = "camera_rgb"}),
                          reference, format);
  }
  auto patches = all_measurements(db, run.id, {.step_prefix = "patch/", .quantity = "reflectance_spectrum"});
  if (patches.empty())
    throw Error(ErrorClass::unsupported,
                "run " + run.id + " (" + run.campaign + ") has no patch readings: a .ti3 pairs patches' device values with "
                "their colour, as a chart-read or characterize-camera run records them",
                "export it as csv or json, which hold every measurement as stored");
  return rx::reference_ti3(run, patches);
}

HttpResponse export_run(ApiContext& ctx, const HttpRequest& req, const std::string& id) {
  const rx::Format format = requested_format(req);
  store::Store& db = ctx.reads();
  auto run = db.run(id);
  if (!run) throw Error(ErrorClass::not_found, "no run with id '" + id + "'");
  HttpResponse r;
  std::string part;
  switch (format) {
    case rx::Format::csv: {
      rx::CsvBody body;
      for_each_measurement(db, id, {}, [&](const store::MeasurementRecord& m) { body.add(m); });
      r.body = body.take();
      break;
    }
    case rx::Format::json: {
      rx::JsonBody body(*run);
      for_each_measurement(db, id, {}, [&](const store::MeasurementRecord& m) { body.add(m); });
      r.body = body.take();
      break;
    }
    case rx::Format::ti3:
      try {
        r.body = ti3_body(db, *run, req, part);
      } catch (const Error& e) {
        if (e.cls() != ErrorClass::unsupported) throw;
        return problem_response(422, "not-exportable", "Not exportable as ti3", e.info().message, e.hint(),
                                {{"instance", req.path}, {"formats", {"csv", "json"}}});
      }
      break;
  }
  r.status = 200;
  r.content_type = rx::media_type(format);
  r.headers["Content-Disposition"] = "attachment; filename=\"" + rx::file_name(*run, format, part) + "\"";
  r.headers["Vary"] = "Accept";
  return r;
}

}  // namespace

HttpResponse get_run_export(ApiContext& ctx, const HttpRequest& req, const PathParams& params) {
  return export_run(ctx, req, params["id"]);
}

}  // namespace colorlab::daemon::routes
