#include "export_response.hpp"

#include "colorlab/api/problem.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::daemon::run_export {

namespace {

// Keyset pages keep one page of rows in memory beside the body being built (a run holds at most ~10^5).
constexpr unsigned kPage = 1000;

template <typename Each>
void for_each_measurement(const MeasurementPages& pages, const std::string& run_id, const store::MeasurementFilter& filter,
                          Each&& each) {
  std::int64_t after = 0;
  for (;;) {
    auto page = pages(run_id, filter, after, kPage);
    for (const auto& m : page.items) each(m);
    if (!page.next_after) return;
    after = *page.next_after;
  }
}

std::vector<store::MeasurementRecord> all_measurements(const MeasurementPages& pages, const std::string& run_id,
                                                       const store::MeasurementFilter& filter) {
  std::vector<store::MeasurementRecord> out;
  for_each_measurement(pages, run_id, filter, [&](const store::MeasurementRecord& m) { out.push_back(m); });
  return out;
}

// Which .ti3 a run makes: a camera's patch values paired with the chart-read it was fitted against, or the
// chart-read's own readings. `part` names the camera format in the file name.
std::string ti3_body(const MeasurementPages& pages, campaigns::RunReader& runs, const store::RunRecord& run,
                     const http::HttpRequest& req, std::string& part) {
  auto first = pages(run.id, {.quantity = "camera_rgb"}, 0, 1);
  if (!first.items.empty()) {
    std::string format = default_camera_format(run, first.items.front());
    if (auto it = req.query.find("camera_format"); it != req.query.end()) format = it->second;
    const std::string reference_run = run.params.is_object() ? run.params.value("reference_run", std::string()) : "";
    if (reference_run.empty())
      throw Error(ErrorClass::unsupported, "run " + run.id + " has camera values but names no reference_run to pair them with",
                  "export it as csv or json");
    const auto reference = campaigns::chart_reference(runs, reference_run);
    part = format;
    return camera_ti3(run, all_measurements(pages, run.id, {.step_prefix = "patch/" + format + "/", .quantity = "camera_rgb"}),
                      reference, format);
  }
  auto patches = all_measurements(pages, run.id, {.step_prefix = "patch/", .quantity = "reflectance_spectrum"});
  // Laid out by hand: clang-format 14 would align the message's second literal under the first line's last one.
  // clang-format off
  if (patches.empty())
    throw Error(ErrorClass::unsupported,
                "run " + run.id + " (" + run.campaign + ") has no patch readings: a .ti3 pairs patches' device values with "
                "their colour, as a chart-read or characterize-camera run records them",
                "export it as csv or json, which hold every measurement as stored");
  // clang-format on
  return reference_ti3(run, patches);
}

}  // namespace

Format requested_format(const http::HttpRequest& req) {
  if (auto it = req.query.find("format"); it != req.query.end()) return parse_format(it->second);
  const auto accept = req.header("accept");
  if (!accept || accept->empty()) return Format::json;
  if (auto f = format_for_accept(*accept)) return *f;
  throw Error(ErrorClass::bad_parameter, "Accept: " + *accept + " names no export format",
              "give format=ti3, csv or json, or Accept: text/x-cgats, text/csv or application/json");
}

http::HttpResponse export_response(const http::HttpRequest& req, Format format, const store::RunRecord& run,
                                   const MeasurementPages& pages, campaigns::RunReader& runs) {
  http::HttpResponse r;
  std::string part;
  switch (format) {
    case Format::csv: {
      CsvBody body;
      for_each_measurement(pages, run.id, {}, [&](const store::MeasurementRecord& m) { body.add(m); });
      r.body = body.take();
      break;
    }
    case Format::json: {
      JsonBody body(run);
      for_each_measurement(pages, run.id, {}, [&](const store::MeasurementRecord& m) { body.add(m); });
      r.body = body.take();
      break;
    }
    case Format::ti3:
      try {
        r.body = ti3_body(pages, runs, run, req, part);
      } catch (const Error& e) {
        if (e.cls() != ErrorClass::unsupported) throw;
        return problem_response(422, "not-exportable", "Not exportable as ti3", e.info().message, e.hint(),
                                {{"instance", req.path}, {"formats", {"csv", "json"}}});
      }
      break;
  }
  r.status = 200;
  r.content_type = media_type(format);
  r.headers["Content-Disposition"] = "attachment; filename=\"" + file_name(run, format, part) + "\"";
  r.headers["Vary"] = "Accept";
  return r;
}

}  // namespace colorlab::daemon::run_export
