#include "locate_commands.hpp"

#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "client_support.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::cli {

using nlohmann::json;

namespace {

struct LocateOptions {
  std::string blob, chart = "sg", corners, reference_run;
  double fraction = 0.6, min_confidence = 0.6;
  bool json = false;
};

// "x1,y1,…,x4,y4" → [[x1, y1], …]: the same text `colorlab analyze locate-chart --corners` takes.
json parse_corners(const std::string& text) {
  std::vector<double> v;
  std::stringstream in(text);
  std::string cell;
  while (std::getline(in, cell, ',')) {
    const auto first = cell.find_first_not_of(" \t"), last = cell.find_last_not_of(" \t");
    cell = first == std::string::npos ? "" : cell.substr(first, last - first + 1);
    try {
      std::size_t used = 0;
      const double x = std::stod(cell, &used);
      if (used != cell.size() || !std::isfinite(x)) throw std::invalid_argument(cell);
      v.push_back(x);
    } catch (const std::exception&) {
      throw Error(ErrorClass::bad_parameter, "--corners: '" + cell + "' is not a number");
    }
  }
  if (v.size() != 8)
    throw Error(ErrorClass::bad_parameter, "--corners needs 8 numbers x1,y1,…,x4,y4, got " + std::to_string(v.size()),
                "the outer corners of the patch grid, the first patch's (A1 / 1) corner first, clockwise");
  json out = json::array();
  for (std::size_t i = 0; i < 4; ++i) out.push_back({v[2 * i], v[2 * i + 1]});
  return out;
}

// Numbers as `colorlab analyze locate-chart` prints them in CSV: six significant digits, no "1156.0".
std::string number(const json& v) {
  if (!v.is_number()) return v.is_string() ? v.get<std::string>() : "";
  std::ostringstream o;
  const double x = v.get<double>();
  o << std::setprecision(6) << (std::abs(x) < 1e-9 ? 0.0 : x);
  return o.str();
}

std::string text(const json& j, const char* key) {
  if (!j.contains(key)) return "";
  return j[key].is_string() ? j[key].get<std::string>() : j[key].dump();
}

// The summary a person reads, then the patches as CSV (the columns `colorlab analyze locate-chart` prints).
void print_human(const json& r) {
  const json& c = r["chart"][0];
  std::cout << "chart " << text(c, "chart") << " in blob " << r["blob"].value("sha256", std::string()) << " ("
            << r["blob"].value("media_type", std::string()) << ", " << r["blob"].value("width", 0) << "×"
            << r["blob"].value("height", 0) << ")\n";
  std::cout << "confidence " << number(c["confidence"]) << ", rotation " << number(c["rotation_deg"]) << "°, "
            << (text(c, "from_corners") == "yes" ? "from the corners given" : "found automatically") << ", "
            << number(c["patches_detected"]) << " of " << r["patches"].size() << " patches detected, reprojection rms "
            << number(c["reprojection_rms_px"]) << " px\n";
  std::cout << "self-check (" << text(c, "check") << "): " << (text(c, "check_passed") == "yes" ? "passed" : "FAILED")
            << ", worst " << text(c, "check_worst_patch") << " " << number(c["check_worst_pct"]) << " %\n";
  std::cout << "corners:";
  for (const auto& k : r["corners"]) std::cout << " " << number(k["x"]) << "," << number(k["y"]);
  std::cout << "\n";
  if (!text(c, "notes").empty()) std::cout << "notes: " << text(c, "notes") << "\n";
  const auto& patches = r["patches"];
  if (patches.empty()) return;
  const bool rgb = patches[0].contains("R");
  std::vector<std::string> cols{"id", "x", "y", "detected"};
  for (const char* k : rgb ? std::vector<const char*>{"R", "G", "B"} : std::vector<const char*>{"value"}) cols.emplace_back(k);
  cols.emplace_back("used");
  std::cout << "\n";
  for (std::size_t i = 0; i < cols.size(); ++i) std::cout << (i ? "," : "") << cols[i];
  std::cout << "\n";
  for (const auto& p : patches) {
    for (std::size_t i = 0; i < cols.size(); ++i) std::cout << (i ? "," : "") << number(p[cols[i]]);
    std::cout << "\n";
  }
}

}  // namespace

void add_locate_commands(CLI::App& app, GlobalOptions& global) {
  auto o = std::make_shared<LocateOptions>();
  auto* c = app.add_subcommand("locate-chart",
                               "Find a ColorChecker SG or 24 in a photograph the daemon keeps (colorlab blobs RUN lists them): corners, "
                               "confidence, every patch's centre and value; refused when unsure (exit 2), then give --corners");
  c->add_option("--blob", o->blob, "the photograph's SHA-256 (a raw, an averaged frame, a TIFF, JPEG or PNG)")->required();
  c->add_option("--chart", o->chart, "sg (ColorChecker SG, 140 patches) or cc24")->capture_default_str();
  c->add_option("--corners", o->corners,
                "x1,y1,x2,y2,x3,y3,x4,y4: outer corners of the patch grid, the first patch's (A1 / 1) corner first, clockwise");
  c->add_option("--reference-run", o->reference_run,
                "a chart-read run of the chart: its patch luminances tell patches as light as the surround from a cover");
  c->add_option("--fraction", o->fraction, "Sampled square side as a fraction of the patch side")->capture_default_str();
  c->add_option("--min-confidence", o->min_confidence, "Refuse below this confidence (0..1)")->capture_default_str();
  c->add_flag("--json", o->json, "print the daemon's JSON (tables chart, corners, patches as `analyze locate-chart --json`)");
  c->callback([&global, o] {
    check_id(o->blob, "a SHA-256", "colorlab blobs RUN lists a run's frames");
    json body{{"chart", o->chart}, {"sample_fraction", o->fraction}, {"min_confidence", o->min_confidence}};
    if (!o->corners.empty()) body["corners"] = parse_corners(o->corners);
    if (!o->reference_run.empty()) {
      check_id(o->reference_run, "a run id", "colorlab runs lists them");
      body["reference_run"] = o->reference_run;
    }
    const json r = make_client(global).post("/v1/blobs/" + o->blob + "/locate-chart", body);
    if (global.json || o->json) {
      std::cout << r.dump(2) << "\n";
    } else {
      print_human(r);
    }
  });
}

}  // namespace colorlab::cli
