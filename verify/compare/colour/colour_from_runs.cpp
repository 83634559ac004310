#include "colour_from_runs.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>

#include "colorlab/analysis/characterization.hpp"
#include "colorlab/analysis/color_difference.hpp"
#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/analysis/scattered_data.hpp"
#include "colorlab/analysis/standard_data.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::verify {

using nlohmann::json;
namespace ca = analysis;

namespace {

constexpr const char* kCharacterize = "characterize-camera";
constexpr const char* kChartRead = "chart-read";

std::string id_of(const json& run) { return run.value("id", std::string("?")); }

Error lacks(const json& run, const std::string& what, const std::string& hint) {
  return Error(ErrorClass::bad_parameter, "run " + id_of(run) + " (" + run.value("campaign", std::string("?")) + ") has no " + what, hint);
}

// The characterize-camera script's result for the raw photograph.
const json& raw_result(const json& run) {
  const json* s = run.contains("summary") ? &run["summary"] : nullptr;
  if (s && s->contains("script")) s = &(*s)["script"];
  if (!s || !s->is_object() || !s->contains("formats") || !(*s)["formats"].contains("raw"))
    throw lacks(run, "raw characterization",
                "verify colour against a finished characterize-camera run whose formats include raw (the comparison reads linear counts)");
  return (*s)["formats"]["raw"];
}

// patch/raw/<id> rows: id -> [r, g, b] counts above black, in the run's order.
std::vector<std::pair<std::string, Rgb3>> raw_patches(const json& run) {
  std::vector<std::pair<std::string, Rgb3>> out;
  for (const auto& m : run["measurements"]) {
    const std::string step = m.value("step", "");
    if (step.rfind("patch/raw/", 0) != 0 || !m.contains("data")) continue;
    const json& rgb = m["data"].contains("rgb") ? m["data"]["rgb"] : json();
    if (!rgb.is_array() || rgb.size() != 3) throw Error(ErrorClass::bad_data, "run " + id_of(run) + "'s " + step + " has no rgb");
    out.emplace_back(step.substr(10), Rgb3{rgb[0].get<double>(), rgb[1].get<double>(), rgb[2].get<double>()});
  }
  if (out.empty())
    throw lacks(run, "chart photograph (no patch/raw/… rows)", "the raw photograph's patch values come from characterize-camera with formats including raw");
  return out;
}

struct ReferencePatch {
  std::vector<double> reflectance;
  double first_nm = 0, step_nm = 0;
  double y = 0;  // the chart-read's Y (D50, Y = 100 for the perfect reflector)
};

std::map<std::string, ReferencePatch> reference_patches(const json& run) {
  std::map<std::string, ReferencePatch> out;
  for (const auto& m : run["measurements"]) {
    if (m.value("step", "").rfind("patch/", 0) != 0 || !m.contains("data")) continue;
    const json& d = m["data"];
    if (!d.contains("id")) continue;
    ReferencePatch p;
    if (d.contains("values") && d["values"].is_array() && d.contains("first_nm") && d.contains("step_nm")) {
      p.reflectance = d["values"].get<std::vector<double>>();
      p.first_nm = d["first_nm"].get<double>();
      p.step_nm = d["step_nm"].get<double>();
    }
    if (d.contains("XYZ") && d["XYZ"].is_array() && d["XYZ"].size() == 3) p.y = d["XYZ"][1].get<double>();
    // The first reading of a re-read patch, as the exported scene takes it.
    out.emplace(d["id"].get<std::string>(), std::move(p));
  }
  if (out.empty()) throw lacks(run, "patch readings", "give the chart-read run the characterization was fitted against");
  return out;
}

ca::FitTarget target_of(const std::string& name) {
  for (auto t : {ca::FitTarget::xyz_then_lab, ca::FitTarget::lab_direct, ca::FitTarget::xyz_lightness_weighted})
    if (name == ca::to_string(t)) return t;
  throw Error(ErrorClass::bad_data, "the characterization's target '" + name + "' is not one colorlab fits");
}

}  // namespace

std::string illuminant_of_lamp(const std::string& lamp) {
  static const std::map<std::string, std::string> table{
      {"D65", "D65"},
      {"D50", "D50"},
      {"A", "A"},
      {"TL84", "F11"},
      {"CWF", "F2"},
  };
  auto it = table.find(lamp);
  if (it == table.end())
    throw Error(ErrorClass::bad_parameter, "lamp " + lamp + " has no standard spectrum to compare colour under",
                "colour is verified under D65, A, TL84 (F11) or CWF (F2)");
  return it->second;
}

std::string chart_read_of(const json& run) {
  if (run.value("campaign", "") != kCharacterize) return {};
  const json& p = run.contains("params") ? run["params"] : json();
  return p.is_object() ? p.value("reference_run", std::string()) : std::string();
}

RefitCharacterization refit_characterization(const json& char_run, const json& chart_read, const std::string& lamp) {
  const json& raw = raw_result(char_run);
  if (!raw.contains("selected") || !raw["selected"].contains("method"))
    throw lacks(char_run, "selected characterization", "run characterize-camera again: its raw result names the selected mapping");
  const json& sel = raw["selected"];
  const std::string method = sel["method"].get<std::string>();
  ca::FitOptions fo;
  fo.target = target_of(sel.value("target", std::string("xyz_then_lab")));

  const auto cam = raw_patches(char_run);
  const auto ref = reference_patches(chart_read);
  // The chart-read's grid (every patch on one, as chart-read writes it) and the lamp's colorimetry on it.
  const ReferencePatch* first = nullptr;
  for (const auto& [id, p] : ref)
    if (!p.reflectance.empty()) first = &p;
  if (!first)
    throw lacks(chart_read, "reflectance spectra",
                "run chart-read again: colour under the cabinet's lamp is computed from the patches' spectra");
  std::vector<double> grid;
  for (std::size_t k = 0; k < first->reflectance.size(); ++k) grid.push_back(first->first_nm + first->step_nm * static_cast<double>(k));
  const ca::ReflectanceIntegrator integ(ca::load_illuminant(illuminant_of_lamp(lamp)), ca::load_observer(ca::Observer::cie1931_2deg), grid);

  ca::ChartData d;
  d.white = integ.white();
  const auto n = static_cast<Eigen::Index>(cam.size());
  d.rgb.resize(n, 3);
  d.xyz.resize(n, 3);
  d.lab.resize(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto& [id, rgb] = cam[static_cast<std::size_t>(i)];
    auto it = ref.find(id);
    if (it == ref.end() || it->second.reflectance.size() != grid.size() || it->second.first_nm != first->first_nm ||
        it->second.step_nm != first->step_nm)
      throw Error(ErrorClass::bad_data, "chart-read run " + id_of(chart_read) + " has no spectrum of patch " + id + " on its grid",
                  "give the chart-read run the characterization was fitted against (its reference_run)");
    Eigen::RowVectorXd r(static_cast<Eigen::Index>(grid.size()));
    // A black patch reads a little below 0 in the instrument's noise; a surface never reflects less than nothing.
    for (std::size_t k = 0; k < grid.size(); ++k) r[static_cast<Eigen::Index>(k)] = std::max(0.0, it->second.reflectance[k]);
    const ca::Xyz x = integ.xyz(r);
    const ca::Lab l = ca::xyz_to_lab(x, d.white);
    d.ids.push_back(id);
    d.rgb.row(i) << rgb[0], rgb[1], rgb[2];
    d.xyz.row(i) << x.X, x.Y, x.Z;
    d.lab.row(i) << l.L, l.a, l.b;
  }
  d.check();

  auto model = std::make_shared<ca::Characterization>(ca::fit_method(method, d, fo));
  // One fold per patch: the selected method without it, applied to it. A spline keeps the λ chosen on every patch
  // (a λ search per fold costs a hundred fits), as characterize-camera's own cross-validation does, and being a
  // linear smoother at fixed λ its held-out predictions come exactly from one solve (spline_loo_targets); a
  // polynomial is refitted per fold (a few terms: microseconds each).
  RefitCharacterization out;
  const auto t0 = std::chrono::steady_clock::now();
  Eigen::MatrixXd held(d.rgb.rows(), 3);
  if (model->spline()) {
    ca::SplineOptions so = ca::spline_options(method, fo);
    so.smoothing = model->spline()->smoothing();
    const Eigen::MatrixXd t = ca::spline_loo_targets(d, so);
    held = fo.target == ca::FitTarget::lab_direct ? t : ca::xyz_rows_to_lab(t, d.white);
  } else {
    std::vector<std::size_t> keep;
    keep.reserve(d.size());
    for (std::size_t i = 0; i < d.size(); ++i) {
      keep.clear();
      for (std::size_t j = 0; j < d.size(); ++j)
        if (j != i) keep.push_back(j);
      held.row(static_cast<Eigen::Index>(i)) = ca::fit_method(method, d.subset(keep), fo).apply(d.rgb.row(static_cast<Eigen::Index>(i)));
    }
  }
  double sum_de = 0;
  for (Eigen::Index i = 0; i < held.rows(); ++i) {
    if (!held.row(i).allFinite())
      throw Error(ErrorClass::bad_data, "patch " + d.ids[static_cast<std::size_t>(i)] + " cannot be predicted without itself by " + method,
                  "the characterization rests on that one patch; run characterize-camera again");
    const ca::Lab ref_lab{d.lab(i, 0), d.lab(i, 1), d.lab(i, 2)};
    out.characterization.cv_lab.push_back(ref_lab);
    out.characterization.cv_error.push_back({held(i, 0) - ref_lab.L, held(i, 1) - ref_lab.a, held(i, 2) - ref_lab.b});
    sum_de += ca::delta_e2000(ref_lab, {held(i, 0), held(i, 1), held(i, 2)});
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.loo_mean_de00 = sum_de / static_cast<double>(d.size());
  out.ids = d.ids;
  const ca::Xyz white = d.white;
  out.characterization.name = "adapted_mapping/raw " + method + " (" + ca::to_string(fo.target) + ", refitted to " +
                              illuminant_of_lamp(lamp) + ")";
  out.characterization.white = white;
  out.characterization.to_xyz = [model, white](const Rgb3& rgb) {
    Eigen::MatrixXd in(1, 3);
    in << rgb[0], rgb[1], rgb[2];
    const Eigen::MatrixXd lab = model->apply(in);
    return ca::lab_to_xyz({lab(0, 0), lab(0, 1), lab(0, 2)}, white);
  };
  return out;
}

BlackBox stored_black_box(const json& char_run) {
  const json& raw = raw_result(char_run);
  const json* bb = raw.contains("approaches") && raw["approaches"].contains("black_box") ? &raw["approaches"]["black_box"] : nullptr;
  if (!bb) {
    std::string why = "not fitted";
    if (raw.contains("not_fitted") && raw["not_fitted"].contains("black_box")) why = raw["not_fitted"]["black_box"].get<std::string>();
    throw Error(ErrorClass::not_found, "run " + id_of(char_run) + " has no black box (§7.4): " + why,
                "characterize-camera fits it on the raw when the chart-read has spectra and the lamp a standard spectrum");
  }
  const json& s = (*bb)["sensitivities"];
  const json& cv = (*bb)["residuals"]["patches"]["cv"];
  BlackBox out;
  out.wavelengths_nm = s.at("wavelengths").get<std::vector<double>>();
  for (int c = 0; c < 3; ++c) out.sensitivity[static_cast<std::size_t>(c)] = s.at(std::string(1, "RGB"[c])).get<std::vector<double>>();
  std::map<std::string, Rgb3> cam;
  for (const auto& [id, rgb] : raw_patches(char_run)) cam.emplace(id, rgb);
  const auto ids = cv.at("ids").get<std::vector<std::string>>();
  for (std::size_t i = 0; i < ids.size(); ++i) {
    auto it = cam.find(ids[i]);
    if (it == cam.end()) continue;
    out.cv_camera.push_back(it->second);
    out.cv_residual.push_back({cv["R"][i].get<double>(), cv["G"][i].get<double>(), cv["B"][i].get<double>()});
  }
  if (out.cv_camera.empty())
    throw Error(ErrorClass::bad_data, "run " + id_of(char_run) + "'s black box stores no per-patch held-out residuals",
                "run characterize-camera again with this colorlab");
  return out;
}

json add_colour(MeasuredScene& scene, const Rendering& rendering, const json& char_run, const json& chart_read) {
  const json& p = char_run.contains("params") ? char_run["params"] : json::object();
  const std::string lamp = p.value("lamp", std::string("D65"));
  if (lamp.empty())
    throw lacks(char_run, "lamp (it photographed the cabinet as it was)", "verify colour against a characterization made under a named lamp");
  if (!scene.lamp.empty() && scene.lamp != lamp)
    throw Error(ErrorClass::bad_parameter,
                "the light runs are compared under " + scene.lamp + " but characterize-camera run " + id_of(char_run) + " photographed under " + lamp,
                "verify one lamp at a time: --lamp " + lamp + " with light runs that measured it, or other runs");
  const auto located = locate_chart_in_rendering(rendering, chart_read);
  std::map<std::string, PixelRect> where;
  for (std::size_t i = 0; i < located.ids.size(); ++i) where[located.ids[i]] = located.regions[i];

  RefitCharacterization ch = refit_characterization(char_run, chart_read, lamp);
  for (const auto& [id, rgb] : raw_patches(char_run)) {
    auto it = where.find(id);
    if (it == where.end()) throw Error(ErrorClass::bad_data, "patch " + id + " of the photograph is not on the chart found in the rendering");
    PatchMeasurement m;
    m.id = id;
    m.camera = rgb;
    m.rendering_region = it->second;
    scene.patches.push_back(m);
  }
  json account{{"characterization", ch.characterization.name},
               {"loo_mean_de00", ch.loo_mean_de00},
               {"loo_seconds", ch.seconds},
               {"chart_in_rendering", {{"confidence", located.confidence}, {"accuracy_px", located.accuracy_px}}},
               {"runs", {id_of(char_run), id_of(chart_read)}}};
  scene.characterization = std::move(ch.characterization);
  if (rendering.encoding == Encoding::spectral) scene.black_box = stored_black_box(char_run);
  scene.locator_accuracy_px = located.accuracy_px;
  scene.lamp = lamp;
  scene.runs.push_back(id_of(char_run));
  scene.runs.push_back(id_of(chart_read));
  return account;
}

MeasuredScene measured_scene_from_runs(const std::vector<json>& runs, const Rendering& rendering, const RunsSceneOptions& options,
                                       json* colour) {
  std::vector<json> light;
  const json* characterize = nullptr;
  const json* chart_read = nullptr;
  for (const auto& run : runs) {
    const std::string campaign = run.value("campaign", "");
    if (!run.contains("measurements") || !run["measurements"].is_array())
      throw Error(ErrorClass::bad_data, "run " + id_of(run) + " came without its measurements");
    const json** slot = campaign == kCharacterize ? &characterize : campaign == kChartRead ? &chart_read
                                                                                           : nullptr;
    if (!slot) {
      light.push_back(run);
      continue;
    }
    if (*slot)
      throw Error(ErrorClass::bad_parameter, "two " + campaign + " runs given (" + id_of(**slot) + ", " + id_of(run) + ")",
                  "verify colour against one characterization at a time");
    *slot = &run;
  }
  if (chart_read && !characterize)
    throw Error(ErrorClass::bad_parameter, "chart-read run " + id_of(*chart_read) + " given without a characterize-camera run",
                "colour is compared through a characterization of the camera: give the characterize-camera run fitted against it");
  MeasuredScene scene;
  if (!light.empty()) scene = scene_from_runs(light, rendering.width, rendering.height, options);
  if (characterize) {
    const std::string ref = chart_read_of(*characterize);
    if (!chart_read || id_of(*chart_read) != ref)
      throw Error(ErrorClass::bad_parameter,
                  "characterize-camera run " + id_of(*characterize) + " was fitted against chart-read run " + ref +
                      (chart_read ? ", not " + id_of(*chart_read) : std::string(", which was not given")),
                  "give its reference_run with --against (colorlab verify fetches it by itself)");
    if (options.light && scene.lamp.empty()) scene.lamp = options.light->lamp;  // --lamp must be the photograph's
    json account = add_colour(scene, rendering, *characterize, *chart_read);
    if (colour) *colour = std::move(account);
  }
  if (light.empty() && !characterize)
    throw Error(ErrorClass::bad_parameter, "no run to verify against",
                "give floor-luminance (and cabinet-grid) runs for the light, a characterize-camera run for the colour");
  return scene;
}

}  // namespace colorlab::verify
