#include "lens_commands.hpp"

#include <array>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "client_support.hpp"
#include "colorlab/analysis/chart_layout.hpp"
#include "colorlab/analysis/chart_locate.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/verify/lens_calibration.hpp"

namespace colorlab::cli {

using nlohmann::json;
namespace ca = colorlab::analysis;

namespace {

struct CalibrateOptions {
  std::vector<std::string> photos;
  std::string camera, lens, focus, chart = "sg", cfa, date;
  double focal_length_mm = 0, black = 0, min_confidence = 0.6;
  int bits = 0;
};

std::string today() {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[16];
  std::strftime(buf, sizeof buf, "%Y-%m-%d", &tm);
  return buf;
}

ca::CfaPattern cfa_of(const std::string& s) {
  if (s == "RGGB" || s == "rggb") return ca::CfaPattern::rggb;
  if (s == "BGGR" || s == "bggr") return ca::CfaPattern::bggr;
  if (s == "GRBG" || s == "grbg") return ca::CfaPattern::grbg;
  if (s == "GBRG" || s == "gbrg") return ca::CfaPattern::gbrg;
  throw Error(ErrorClass::bad_parameter, "--cfa must be RGGB, BGGR, GRBG or GBRG, not '" + s + "'");
}

// Each photograph located as `colorlab analyze locate-chart` locates it (no lens: the lens is what is being
// calibrated); its detected patch centres, as photographed, are the calibration points (calibrate_lens_from_chart,
// which the lens-calibration campaign shares).
verify::LensCalibration calibrate(const CalibrateOptions& o) {
  const ca::ChartType type = ca::chart_type_from_string(o.chart);
  std::vector<verify::ObservedCentres> photographs;
  int width = 0, height = 0;
  for (const auto& path : o.photos) {
    const ca::Photo photo = ca::read_photo(path);
    ca::PhotoView view = photo.view();
    view.black_level = o.black;
    view.bit_depth = o.bits;
    if (!o.cfa.empty()) view.cfa = cfa_of(o.cfa);
    if (width == 0) width = view.width, height = view.height;
    if (view.width != width || view.height != height)
      throw Error(ErrorClass::bad_parameter,
                  path + " is " + std::to_string(view.width) + " × " + std::to_string(view.height) +
                      ", the first photograph " + std::to_string(width) + " × " + std::to_string(height),
                  "one calibration holds for one photograph size: use the same camera settings throughout");
    ca::ChartLocation loc;
    try {
      ca::LocateOptions lo;
      lo.min_confidence = o.min_confidence;
      loc = ca::locate_chart(view, type, lo);
    } catch (const Error& e) {
      throw Error(e.cls(), path + ": " + e.what(), e.hint());
    }
    verify::ObservedCentres observed;
    for (const auto& s : loc.patches) observed.push_back(s.detected ? std::optional(std::array{s.observed.x, s.observed.y}) : std::nullopt);
    photographs.push_back(std::move(observed));
  }
  verify::LensIdentity who{o.camera, o.lens, o.focus, o.date.empty() ? today() : o.date, std::nullopt};
  if (o.focal_length_mm > 0) who.focal_length_mm = o.focal_length_mm;
  return verify::calibrate_lens_from_chart(o.chart, photographs, width, height, who, "colorlab lens calibrate");
}

}  // namespace

void add_lens_commands(CLI::App& app, GlobalOptions& global) {
  auto* lens = app.add_subcommand("lens", "The lab's lens calibrations ([[lens]] in the lab configuration; docs/verify.md)");
  lens->require_subcommand(1);

  auto o = std::make_shared<CalibrateOptions>();
  auto* cal = lens->add_subcommand(
      "calibrate", "Calibrate a lens from photographs of the chart at several poses (OpenCV calibrateCamera); prints the "
                   "[[lens]] table for colorlabd.toml (--json: the calibration as GET /v1/lab/lenses gives it)");
  cal->add_option("PHOTO", o->photos, "3 or more photographs (TIFF, PNG, JPEG, PGM; raw mosaic with --cfa), chart tilted and "
                                      "placed across the frame")
      ->required();
  cal->add_option("--camera", o->camera, "the camera body, e.g. \"Canon EOS 20D #1\"")->required();
  cal->add_option("--lens", o->lens, "the lens, e.g. \"EF 50mm f/1.8 II\"")->required();
  cal->add_option("--focal-length-mm", o->focal_length_mm, "a zoom's focal length setting");
  cal->add_option("--focus", o->focus, "the focus setting, where it was fixed (e.g. \"1.2 m\")");
  cal->add_option("--chart", o->chart, "sg or cc24")->capture_default_str();
  cal->add_option("--cfa", o->cfa, "the photographs are raw mosaics with this pattern (RGGB, …)");
  cal->add_option("--black", o->black, "black level of the counts");
  cal->add_option("--bits", o->bits, "significant bits (12 for a 12-bit raw)");
  cal->add_option("--date", o->date, "the calibration's date (default: today, UTC)");
  cal->add_option("--min-confidence", o->min_confidence,
                  "refuse a photograph the locator is less sure of (0..1; only its detected patches are used)")
      ->capture_default_str();
  cal->callback([&global, o] {
    const verify::LensCalibration l = calibrate(*o);
    if (global.json) std::cout << verify::lens_to_json(l).dump(2) << "\n";
    else std::cout << verify::lens_to_toml(l);
  });

  auto run = std::make_shared<std::string>();
  auto* from_run = lens->add_subcommand(
      "from-run", "The calibration a lens-calibration run made (GET /v1/runs/RUN): its [[lens]] table for colorlabd.toml "
                  "(--json: the calibration as GET /v1/lab/lenses gives it)");
  from_run->add_option("RUN", *run, "the lens-calibration run's id")->required();
  from_run->callback([&global, run] {
    check_id(*run, "a run id", "colorlab runs lists them");
    const json r = make_client(global).get("/v1/runs/" + *run);
    const std::string campaign = r.value("campaign", std::string());
    const json* lens = nullptr;
    if (r.contains("summary") && r["summary"].is_object() && r["summary"].contains("script") && r["summary"]["script"].is_object() &&
        r["summary"]["script"].contains("lens"))
      lens = &r["summary"]["script"]["lens"];
    if (!lens)
      throw Error(ErrorClass::bad_parameter,
                  "run " + *run + " (" + (campaign.empty() ? "?" : campaign) + ", " + r.value("status", std::string("?")) +
                      ") holds no lens calibration",
                  "give a lens-calibration run that finished (colorlab runs lists them)");
    const verify::LensCalibration l = verify::lens_from_json(*lens, "run " + *run);
    if (global.json) std::cout << verify::lens_to_json(l).dump(2) << "\n";
    else std::cout << verify::lens_to_toml(l);
  });

  auto lab = std::make_shared<std::string>();
  auto* list = lens->add_subcommand("list", "The lab's lens calibrations: the daemon's (GET /v1/lab/lenses) or a lab file's");
  list->add_option("--lab", *lab, "a TOML lab file's [[lens]] tables instead of the daemon's");
  list->callback([&global, lab] {
    json items = json::array();
    if (!lab->empty()) {
      for (const auto& l : verify::lenses_from_file(*lab)) items.push_back(verify::lens_to_json(l));
    } else {
      const json answer = make_client(global).get("/v1/lab/lenses");  // a body that is not JSON: Error, not a crash
      if (!answer.is_object() || !answer.contains("items") || !answer["items"].is_array())
        throw Error(ErrorClass::bad_data, "GET /v1/lab/lenses: no items in the daemon's answer");
      for (const auto& i : answer["items"]) items.push_back(verify::lens_to_json(verify::lens_from_json(i, "GET /v1/lab/lenses")));
    }
    print(global, json{{"items", items}}, [](const json& j) {
      if (j["items"].empty()) return std::string("no lens calibrations (add [[lens]] tables: colorlab lens calibrate prints one)\n");
      std::string s;
      for (const auto& l : j["items"]) {
        char line[256];
        std::snprintf(line, sizeof line, ": %d × %d px, fx %.1f ± %.1f, fy %.1f ± %.1f, cx %.1f ± %.1f, cy %.1f ± %.1f, k1 %.4f ± %.4f, k2 %.4f ± %.4f",
                      l["width_px"].get<int>(), l["height_px"].get<int>(), l["fx"].get<double>(), l["sigma"]["fx"].get<double>(),
                      l["fy"].get<double>(), l["sigma"]["fy"].get<double>(), l["cx"].get<double>(), l["sigma"]["cx"].get<double>(),
                      l["cy"].get<double>(), l["sigma"]["cy"].get<double>(), l["k1"].get<double>(), l["sigma"]["k1"].get<double>(),
                      l["k2"].get<double>(), l["sigma"]["k2"].get<double>());
        s += l["name"].get<std::string>() + line + " (" + l["source"].get<std::string>() + ", " + l["date"].get<std::string>() + ")\n";
      }
      return s;
    });
  });
}

}  // namespace colorlab::cli
