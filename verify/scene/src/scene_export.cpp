#include "colorlab/verify/scene_export.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <optional>
#include <string>

#include "colorlab/analysis/standard_data.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::verify {

using nlohmann::json;

namespace {

constexpr double mm = 1e-3;   // scene.json is in metres, Blender's unit
constexpr double km = 683.0;  // lm/W, maximum luminous efficacy
// The SG's outer size (dissertation appendix C.2: 21.59 × 27.94 cm); a CC24 is given the same board.
constexpr double chart_w_mm = 279.4, chart_h_mm = 215.9;

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

[[noreturn]] void bad(const std::string& what, const std::string& hint = "see docs/verify.md, \"The measured scene\"") {
  throw Error(ErrorClass::bad_parameter, "scene: " + what, hint);
}

[[noreturn]] void malformed(const std::string& run, const std::string& what) {
  throw Error(ErrorClass::bad_data, "scene: run " + run + ": " + what,
              "give the run's JSON export (colorlab export RUN -f json) or its id");
}

struct Tabulated {  // one spectrum on its own (uniform or not) grid
  std::vector<double> nm, v;
  double at(double x) const {  // linear, 0 outside: a lamp or observer table simply ends
    if (nm.empty() || x < nm.front() || x > nm.back()) return 0.0;
    std::size_t i = 1;
    while (i < nm.size() - 1 && nm[i] < x) ++i;
    const double t = (x - nm[i - 1]) / (nm[i] - nm[i - 1]);
    return v[i - 1] + t * (v[i] - v[i - 1]);
  }
};

Tabulated row(const analysis::SpectralSet& s, std::size_t r) {
  Tabulated t{s.wavelengths, {}};
  for (std::size_t i = 0; i < s.wavelengths.size(); ++i)
    t.v.push_back(s.values(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(i)));
  return t;
}

const char* cie_name(const std::string& lamp) {
  if (lamp == "D65") return "D65";
  if (lamp == "TL84") return "F11";
  if (lamp == "CWF") return "F2";
  if (lamp == "A") return "A";
  bad("lamp " + lamp + " has no named standard spectrum a renderer could be given",
      "export the visible lamps (D65, TL84, CWF, A); the UV tube's light is not modelled for renderers");
}

// ∫ S ȳ dλ on the lamp table's own grid (trapezoids), as the photometric definition wants it.
double photopic(const Tabulated& s, const Tabulated& ybar) {
  double sum = 0.0;
  for (std::size_t i = 1; i < s.nm.size(); ++i)
    sum += 0.5 * (s.v[i] * ybar.at(s.nm[i]) + s.v[i - 1] * ybar.at(s.nm[i - 1])) * (s.nm[i] - s.nm[i - 1]);
  return sum;
}

struct Runs {
  const json* chart = nullptr;
  const json* grid = nullptr;
  const json* camera = nullptr;  // characterize-camera: the located chart
};

std::string run_id(const json& doc) {
  const auto& r = doc.value("run", json::object());
  return r.value("id", std::string("(no id)"));
}

Runs classify(const std::vector<json>& runs) {
  Runs out;
  for (const auto& doc : runs) {
    if (!doc.is_object() || !doc.contains("run") || !doc["run"].is_object() || !doc.contains("measurements") ||
        !doc["measurements"].is_array())
      malformed(run_id(doc), "not a run export ({run, measurements})");
    const std::string campaign = doc["run"].value("campaign", std::string());
    const json** slot = campaign == "chart-read"            ? &out.chart
                        : campaign == "cabinet-grid"        ? &out.grid
                        : campaign == "characterize-camera" ? &out.camera
                                                            : nullptr;
    if (!slot) bad("run " + run_id(doc) + " is a " + (campaign.empty() ? "run of no campaign" : campaign) +
                   " run; a scene is made of one chart-read, at most one cabinet-grid and at most one "
                   "characterize-camera run");
    if (*slot) bad("two " + campaign + " runs (" + run_id(**slot) + ", " + run_id(doc) + "): give one");
    *slot = &doc;
  }
  if (!out.chart) bad("no chart-read run: the patches' reflectance spectra come from one", "colorlab runs --campaign chart-read lists them");
  return out;
}

json spectrum(double first, double step, const std::vector<double>& v) {
  return {{"first_nm", first}, {"step_nm", step}, {"values", v}};
}

// The charts a chart-read reads (campaigns/scripts/chart-read.lua): the patch grid, ids in the run's order.
// Kept here rather than taken from analysis/'s chart locator, which is an optional OpenCV target.
struct Layout {
  std::string name;
  int columns = 0, rows = 0;
  double patch_fraction = 0;  // patch side / pitch
  std::vector<std::string> ids;
  std::vector<int> column, row;
  std::optional<int> index_of(const std::string& id) const {
    for (std::size_t i = 0; i < ids.size(); ++i)
      if (ids[i] == id) return static_cast<int>(i);
    return std::nullopt;
  }
};

Layout layout_of(const std::string& chart, const std::string& run) {
  Layout l;
  const std::string c = upper(chart);
  if (c == "SG" || c == "SG140") {
    // ColorChecker SG: columns A..N, rows 1..10, 15 mm patches at a 19 mm pitch; file order A1, A2, …, B1, …
    l = {"ColorChecker SG", 14, 10, 15.0 / 19.0, {}, {}, {}};
    for (int col = 0; col < 14; ++col)
      for (int r = 0; r < 10; ++r) {
        l.ids.push_back(std::string(1, static_cast<char>('A' + col)) + std::to_string(r + 1));
        l.column.push_back(col), l.row.push_back(r);
      }
  } else if (c == "CC24" || c == "24") {
    l = {"ColorChecker 24", 6, 4, 0.8, {}, {}, {}};
    for (int r = 0; r < 4; ++r)
      for (int col = 0; col < 6; ++col) {
        l.ids.push_back(std::to_string(r * 6 + col + 1));
        l.column.push_back(col), l.row.push_back(r);
      }
  } else {
    malformed(run, "chart \"" + chart + "\" is neither sg nor cc24");
  }
  return l;
}

// The chart: placement from the cabinet, each patch's spectrum exactly as the chart-read stored it.
json chart_part(const CabinetGeometry& cab, const json& doc, double& first_nm, double& step_nm, std::size_t& bands) {
  const std::string id = run_id(doc);
  const json params = doc["run"].value("params", json::object());
  const std::string chart = params.value("chart", std::string("sg"));
  const double pitch = params.value("pitch_mm", 19.0);
  const Layout layout = layout_of(chart, id);
  const double size = layout.patch_fraction * pitch;
  // The patch grid is centred on the board (as on an SG): patch centres at ((c − (columns−1)/2)·pitch,
  // (r − (rows−1)/2)·pitch) from the board's centre, y down the board.
  json patches = json::array();
  std::vector<bool> seen(layout.ids.size(), false);
  bool grid_known = false;
  for (const auto& m : doc["measurements"]) {
    if (m.value("quantity", std::string()) != "reflectance_spectrum") continue;
    const json& d = m.value("data", json::object());
    if (!d.contains("id") || !d.contains("values") || !d.contains("first_nm") || !d.contains("step_nm"))
      malformed(id, "a reflectance_spectrum measurement lacks id, first_nm, step_nm or values");
    const std::string pid = d["id"].get<std::string>();
    const auto idx = layout.index_of(pid);
    if (!idx) malformed(id, "patch \"" + pid + "\" is not on a " + layout.name);
    if (seen[static_cast<std::size_t>(*idx)]) continue;  // a re-read patch: the first stored reading stands
    seen[static_cast<std::size_t>(*idx)] = true;
    const auto values = d["values"].get<std::vector<double>>();
    const double f = d["first_nm"].get<double>(), s = d["step_nm"].get<double>();
    if (!grid_known) {
      first_nm = f, step_nm = s, bands = values.size(), grid_known = true;
    } else if (f != first_nm || s != step_nm || values.size() != bands) {
      malformed(id, "patch " + pid + " is on another wavelength grid than the others");
    }
    const auto k = static_cast<std::size_t>(*idx);
    const double bx = (layout.column[k] - (layout.columns - 1) / 2.0) * pitch, by = (layout.row[k] - (layout.rows - 1) / 2.0) * pitch;
    const double fx = cab.chart_center_x_mm + bx, fy = cab.chart_center_y_mm - by;
    patches.push_back({
        {"id", pid},
        {"index", *idx},
        {"center_m", {fx * mm, fy * mm}},
        {"size_m", size * mm},
        {"reflectance", spectrum(f, s, values)},
    });
  }
  for (int i = 0; i < static_cast<int>(layout.ids.size()); ++i)
    if (!seen[static_cast<std::size_t>(i)]) malformed(id, "patch " + layout.ids[static_cast<std::size_t>(i)] + " was not read");
  std::sort(patches.begin(), patches.end(), [](const json& a, const json& b) { return a["index"] < b["index"]; });
  return {{"name", layout.name},
          {"source_run", id},
          {"center_m", {cab.chart_center_x_mm * mm, cab.chart_center_y_mm * mm}},
          {"size_m", {chart_w_mm * mm, chart_h_mm * mm}},
          {"orientation", "flat on the floor, row 1 (the top edge) towards the back, column A at the left"},
          {"surround_reflectance", 0.05},
          {"surround_note", "the board between the patches is not measured: a flat 0.05 (the SG's dark surround)"},
          {"patches", patches}};
}

struct GridFit {
  double luminance = 0;
  std::size_t spots = 0;
  double rms_pct = 0, standard_error_pct = 0;
};

// Emitter luminance L from LS-110 floor readings m_i = ρ L F_i by least squares (one factor per lamp).
std::optional<GridFit> fit_luminance(const CabinetGeometry& cab, const CabinetEmitter& e, const json& doc,
                                     const std::string& lamp, double dimmer, json& spots) {
  double mg = 0, gg = 0;
  std::vector<std::pair<double, double>> pts;
  for (const auto& m : doc["measurements"]) {
    if (m.value("quantity", std::string()) != "luminance") continue;
    const json& d = m.value("data", json::object());
    if (upper(d.value("lamp", std::string())) != lamp) continue;
    if (std::abs(d.value("dimmer_percent", -1.0) - dimmer) > 1e-9) continue;
    if (!d.contains("row") || !d.contains("col") || !m.contains("value") || !m["value"].is_number())
      malformed(run_id(doc), "a luminance measurement lacks row, col or value");
    const int r = d["row"].get<int>(), c = d["col"].get<int>();
    const double x = (c + 0.5) * cab.grid_pitch_x_mm, y = (r + 0.5) * cab.grid_pitch_y_mm;
    const double g = cab.floor_reflectance * form_factor(e, cab.height_mm, x, y), v = m["value"].get<double>();
    mg += v * g, gg += g * g;
    pts.emplace_back(v, g);
    spots.push_back({{"lamp", lamp}, {"row", r}, {"col", c}, {"position_m", {x * mm, y * mm}}, {"luminance_cd_m2", v}});
  }
  if (pts.empty() || !(gg > 0)) return std::nullopt;
  GridFit f;
  f.luminance = mg / gg;
  f.spots = pts.size();
  double ss = 0;
  for (const auto& [v, g] : pts) ss += std::pow((v - f.luminance * g) / (f.luminance * g), 2);
  f.rms_pct = 100.0 * std::sqrt(ss / static_cast<double>(pts.size()));
  f.standard_error_pct = f.rms_pct / std::sqrt(static_cast<double>(pts.size()));
  return f;
}

json nominal_camera(const CabinetGeometry& cab) {
  // Estimated, not measured: the dissertation's setup (Figs. 27–29) aims the camera at the chart's centre at
  // 48° from its normal, from the open front; the distance and lens are assumed (a 50 mm lens on the EOS
  // 20D's 22.5 × 15 mm sensor, the chart across ~70 % of the frame width).
  const double angle = 48.0 * std::numbers::pi / 180.0, f_mm = 50.0, sensor_w = 22.5;
  const double distance = f_mm * chart_w_mm / (0.7 * sensor_w);
  const double cx = cab.chart_center_x_mm, cy = cab.chart_center_y_mm;
  return {{"position_m", {cx * mm, (cy - distance * std::sin(angle)) * mm, distance * std::cos(angle) * mm}},
          {"look_at_m", {cx * mm, cy * mm, 0.0}},
          {"up", {0.0, 0.0, 1.0}},
          {"focal_length_mm", f_mm},
          {"sensor_mm", {sensor_w, 15.0}},
          {"resolution_px", {3504, 2336}},
          {"distortion", {{"k1", 0.0}, {"k2", 0.0}}},
          {"estimated", true},
          {"how", "nominal: the dissertation's camera geometry (aimed at the chart centre, 48° from the chart's "
                  "normal, from the front; Figs. 27–29) with an assumed 50 mm lens and distance; give a "
                  "characterize-camera run for the pose from the located chart (docs/verify.md)"}};
}

// The located chart of a characterize-camera run: its chart/<format> row (raw preferred: §7.3 and §7.4 use it).
const json* located_chart(const json& doc) {
  const json* found = nullptr;
  for (const auto& m : doc["measurements"]) {
    const std::string step = m.value("step", std::string());
    if (step.rfind("chart/", 0) != 0 || !m.contains("data") || !m["data"].is_object() || !m["data"].contains("corners"))
      continue;
    if (step == "chart/raw") return &m;
    if (!found) found = &m;
  }
  return found;
}

double number_in(const json& d, const char* key, const std::string& run) {
  if (!d.contains(key) || !d[key].is_number()) malformed(run, std::string("the located chart has no number '") + key + "'");
  return d[key].get<double>();
}

// The locator's grid corners (chart_layout.cpp: patch pitch 1, the SG's patches 15/19 of it, a CC24's 0.9): their
// places on the floor, the chart lying as chart_part puts it (row 1 at the back, column A at the left).
std::array<std::array<double, 3>, 4> grid_corners_mm(const CabinetGeometry& cab, const Layout& layout, double pitch) {
  const double fraction = layout.columns == 14 ? 15.0 / 19.0 : 0.9;
  const double hw = (layout.columns - 1 + fraction) * pitch / 2, hh = (layout.rows - 1 + fraction) * pitch / 2;
  const double cx = cab.chart_center_x_mm, cy = cab.chart_center_y_mm;
  return {{{cx - hw, cy + hh, 0.0}, {cx + hw, cy + hh, 0.0}, {cx + hw, cy - hh, 0.0}, {cx - hw, cy - hh, 0.0}}};
}

json camera_part(const CabinetGeometry& cab, const json& chart_doc, const json* camera_doc, const SceneExportOptions& o) {
  if (!camera_doc) return nominal_camera(cab);
  const std::string id = run_id(*camera_doc);
  const json* row = located_chart(*camera_doc);
  if (!row) malformed(id, "no chart/<format> row with corners: the characterize-camera run located no chart");
  const json& d = (*row)["data"];
  const std::string format = d.value("format", std::string("raw"));
  const double width = number_in(d, "width", id), height = number_in(d, "height", id);
  if (!(width > 0 && height > 0)) malformed(id, "the located chart's photograph has no size");
  ChartSighting s;
  const json& c = d["corners"];
  if (!c.is_array() || c.size() != 4) malformed(id, "the located chart has not four corners");
  for (std::size_t i = 0; i < 4; ++i) {
    if (!c[i].is_array() || c[i].size() != 2 || !c[i][0].is_number() || !c[i][1].is_number())
      malformed(id, "corner " + std::to_string(i) + " of the located chart is not [x, y]");
    s.corners_px[i] = {c[i][0].get<double>(), c[i][1].get<double>()};
  }
  // The locator's stated accuracy: the RMS of the detected patch centres against its fit (what verify's
  // misregistration source uses); a corner extrapolated from 140 centres is known better, so this bounds it.
  s.accuracy_px = d.contains("reprojection_rms_px") && d["reprojection_rms_px"].is_number()
                      ? d["reprojection_rms_px"].get<double>()
                      : 0.5;
  const json params = chart_doc["run"].value("params", json::object());
  const Layout layout = layout_of(params.value("chart", std::string("sg")), run_id(chart_doc));
  s.corners_mm = grid_corners_mm(cab, layout, params.value("pitch_mm", 19.0));

  // Intrinsics: the lab's lens calibration when given; else the EOS 20D's nominal 50 mm on its 22.5 mm-wide sensor
  // (no run stores the photograph's EXIF), principal point at the centre, no distortion.
  const double sensor_w = 22.5;
  CameraIntrinsics k;
  std::string source;
  json calibration = nullptr;
  const std::optional<LensCalibration> stored =
      o.lens ? std::nullopt : choose_lens(o.lenses, o.lens_name, static_cast<int>(width), static_cast<int>(height));
  if (o.lens) {
    k = *o.lens;
    source = o.lens_source.empty() ? "the lab's lens calibration" : o.lens_source;
  } else if (stored) {
    k = stored->intrinsics;
    source = "lens calibration \"" + stored->name() + "\" (" + (stored->source.empty() ? "source not stated" : stored->source) +
             (stored->date.empty() ? "" : ", " + stored->date) + ")";
    calibration = lens_to_json(*stored);
  } else {
    k.fx = k.fy = 50.0 * width / sensor_w;
    k.cx = width / 2 - 0.5, k.cy = height / 2 - 0.5;
    source = "nominal: an assumed 50 mm lens on the EOS 20D's 22.5 mm-wide sensor (no lens calibration given; no "
             "run stores the photograph's EXIF focal length)";
  }
  const CameraPose p = pose_from_chart(s, k, stored ? stored->sigma : CameraIntrinsics{});
  const auto& z = p.axes[2];
  // Where the optical axis meets the floor (z = 0), for renderers that aim by a target.
  const double t = z[2] < 0 ? -p.position_mm[2] / z[2] : 1000.0;
  json axes = json::array();
  for (const auto& a : p.axes) axes.push_back({a[0], a[1], a[2]});
  json corners = json::array();
  for (const auto& q : s.corners_px) corners.push_back({q[0], q[1]});
  // Laid out by hand: clang-format 14 joins the break inside "how"'s message into one 207-column line.
  // clang-format off
  return {{"position_m", {p.position_mm[0] * mm, p.position_mm[1] * mm, p.position_mm[2] * mm}},
          {"look_at_m", {(p.position_mm[0] + t * z[0]) * mm, (p.position_mm[1] + t * z[1]) * mm, (p.position_mm[2] + t * z[2]) * mm}},
          {"up", {-p.axes[1][0], -p.axes[1][1], -p.axes[1][2]}},
          {"axes", axes},
          {"axes_note", "the camera's x (image right), y (image down) and z (optical axis, forward) in the cabinet's frame: OpenCV's camera"},
          {"focal_length_mm", k.fx * sensor_w / width},
          {"sensor_mm", {sensor_w, sensor_w * height / width}},
          {"resolution_px", {width, height}},
          {"intrinsics_px", {{"fx", k.fx}, {"fy", k.fy}, {"cx", k.cx}, {"cy", k.cy}}},
          {"distortion", {{"k1", k.k1}, {"k2", k.k2}}},
          {"intrinsics_source", source},
          {"estimated", !o.lens && !stored},
          {"lens_calibration", calibration},
          {"pose", {{"source", "located chart"}, {"run", id}, {"format", format}, {"corners_px", corners},
                    {"corner_accuracy_px", s.accuracy_px}, {"reprojection_px", p.reprojection_px},
                    {"position_sigma_m", {p.position_sigma_mm[0] * mm, p.position_sigma_mm[1] * mm, p.position_sigma_mm[2] * mm}},
                    {"axis_sigma_deg", p.axis_sigma_deg},
                    {"sigma_sources", {{"corners", {{"position_m", {p.position_sigma_corners_mm[0] * mm, p.position_sigma_corners_mm[1] * mm, p.position_sigma_corners_mm[2] * mm}}, {"axis_deg", p.axis_sigma_corners_deg}}},
                                       {"lens_calibration", {{"position_m", {p.position_sigma_lens_mm[0] * mm, p.position_sigma_lens_mm[1] * mm, p.position_sigma_lens_mm[2] * mm}}, {"axis_deg", p.axis_sigma_lens_deg}}}}}}},
          {"how", "solvePnP (OpenCV, IPPE) of the chart locator's four outer grid corners on the " + format +
                      " photograph against the chart's geometry where the cabinet puts it, with the intrinsics above; "
                      "σ from the corners' stated accuracy and the lens calibration's own σ (none for --lens or a nominal "
                      "lens) through the solution's Jacobian"}};
  // clang-format on
}

}  // namespace

json export_scene(const CabinetGeometry& cab, const std::vector<json>& runs, const SceneExportOptions& o) {
  validate(cab);
  if (!(o.dimmer_percent > 0.0 && o.dimmer_percent <= 100.0)) bad("dimmer must be in (0, 100] %");
  const Runs r = classify(runs);
  double first_nm = 380, step_nm = 10;
  std::size_t bands = 0;
  json chart = chart_part(cab, *r.chart, first_nm, step_nm, bands);
  std::vector<double> centres;
  for (std::size_t i = 0; i < bands; ++i) centres.push_back(first_nm + step_nm * static_cast<double>(i));

  std::vector<std::string> lamps;
  for (const auto& l : o.lamps) lamps.push_back(upper(l));
  if (lamps.empty() && r.grid) {
    for (const auto& m : (*r.grid)["measurements"]) {
      const json& d = m.value("data", json::object());
      if (m.value("quantity", std::string()) != "luminance" || std::abs(d.value("dimmer_percent", -1.0) - o.dimmer_percent) > 1e-9) continue;
      const std::string l = upper(d.value("lamp", std::string()));
      if (!l.empty() && std::find(lamps.begin(), lamps.end(), l) == lamps.end()) lamps.push_back(l);
    }
  }
  if (lamps.empty()) lamps.push_back("D65");

  const auto ybar_set = analysis::load_observer(analysis::Observer::cie1931_2deg);
  const Tabulated ybar = row(ybar_set, ybar_set.require("ybar"));
  json lamp_parts = json::array(), grid_spots = json::array();
  for (const auto& lamp : lamps) {
    const CabinetEmitter* e = emitter_of(cab, lamp);
    if (!e) bad("lamp " + lamp + " has no emitter in the cabinet's configuration", "add a [[cabinet.emitter]] for it");
    const char* cie = cie_name(lamp);
    const auto table = analysis::load_illuminant(cie);
    const Tabulated spd = row(table, 0);
    json level;
    double luminance = 0;
    std::optional<GridFit> fit;
    if (r.grid) fit = fit_luminance(cab, *e, *r.grid, lamp, o.dimmer_percent, grid_spots);
    if (fit) {
      luminance = fit->luminance;
      level = {
          {"source", "fitted"},
          {"run", run_id(*r.grid)},
          {"spots", fit->spots},
          {"rms_residual_pct", fit->rms_pct},
          {"standard_error_pct", fit->standard_error_pct},
          {"how", "least squares of the LS-110 floor readings at this dimmer against ρ_floor·L·F(spot), F the "
                  "emitter's analytic form factor: one factor per lamp"},
      };
    } else if (e->luminance_cd_m2 > 0 && o.dimmer_percent == 100.0) {
      luminance = e->luminance_cd_m2;
      level = {{"source", "configured"}, {"how", "the lab configuration's [[cabinet.emitter]] luminance_cd_m2 at 100 %"}};
    } else {
      char level_text[32];
      std::snprintf(level_text, sizeof level_text, "%g", o.dimmer_percent);
      bad("no LS-110 readings of " + lamp + " at " + level_text + " % and no configured luminance" +
              (o.dimmer_percent != 100.0 && e->luminance_cd_m2 > 0 ? " at that level" : ""),
          "give a cabinet-grid run that measured it, or its emitter's luminance_cd_m2 in [cabinet] (at 100 %)");
    }
    // Spectral radiance L(λ) = k·S(λ) with 683·∫L ȳ dλ equal to the emitter's luminance.
    const double k = luminance / (km * photopic(spd, ybar));
    std::vector<double> radiance;
    for (double nm : centres) radiance.push_back(k * spd.at(nm));
    lamp_parts.push_back(
        {{"name", lamp},
         {"dimmer_percent", o.dimmer_percent},
         {"emitter", {
                         {"center_m", {e->x_mm * mm, e->y_mm * mm, cab.height_mm * mm}},
                         {"size_m", {e->length_mm * mm, e->width_mm * mm}},
                         {"normal", {0, 0, -1}},
                         {"kind", "Lambertian rectangle, emitting downwards only"},
                     }},
         {"luminance_cd_m2", luminance},
         {"level", level},
         {"spectral_radiance", spectrum(first_nm, step_nm, radiance)},
         {"spectrum_source", std::string("named standard: CIE ") + cie + " (colord's table; no run measured this lamp's spectrum)"}});
  }
  std::vector<double> ybar_bands;
  for (double nm : centres) ybar_bands.push_back(ybar.at(nm));

  return {{"schema", scene_schema},
          {"units", {{"length", "m"}, {"spectral_radiance", "W·sr⁻¹·m⁻²·nm⁻¹"}, {"luminance", "cd/m²"}}},
          {"coordinates", "x from the cabinet's left inner wall, y from its open front edge towards the back, z up from the floor"},
          {"bands", {
                        {"first_nm", first_nm},
                        {"step_nm", step_nm},
                        {"count", bands},
                        {"ybar", ybar_bands},
                        {"note", "each band is its centre's value held over ±step/2 (box bands, JCGT 2021's default)"},
                    }},
          {"cabinet", {
                          {"width_m", cab.width_mm * mm},
                          {"depth_m", cab.depth_mm * mm},
                          {"height_m", cab.height_mm * mm},
                          {"front", "open"},
                          {"walls_reflectance", 0.0},
                          {"walls_note", "black: the exported scene carries direct light only, as the simulator's geometric cabinet computes it"},
                          {"floor_reflectance", cab.floor_reflectance},
                          {"grid_pitch_m", {cab.grid_pitch_x_mm * mm, cab.grid_pitch_y_mm * mm}},
                      }},
          {"lamps", lamp_parts},
          {"chart", chart},
          {"camera", camera_part(cab, *r.chart, r.camera, o)},
          {"luminance_scale", {
                                  {"instrument", "LS-110"},
                                  {"source_run", r.grid ? json(run_id(*r.grid)) : json(nullptr)},
                                  {"dimmer_percent", o.dimmer_percent},
                                  {"spots", grid_spots},
                              }}};
}

void write_scene(const json& scene, const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error(ErrorClass::io_error, "scene: cannot create " + dir.string() + ": " + ec.message());
  auto put = [&](const std::string& name, std::string_view text) {
    std::ofstream f(dir / name, std::ios::binary | std::ios::trunc);
    f << text;
    if (!f.flush()) throw Error(ErrorClass::io_error, "scene: cannot write " + (dir / name).string());
  };
  put("scene.json", scene.dump(1) + "\n");
  put("build_scene.py", build_scene_script());
}

}  // namespace colorlab::verify
