#include "colorlab/campaigns/characterize.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "colorlab/analysis/characterization.hpp"
#include "colorlab/analysis/icc_profile.hpp"
#include "colorlab/analysis/rgb_spaces.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::campaigns {

using nlohmann::json;
namespace ca = analysis;

namespace {

Error bad(const std::string& what, const std::string& hint = {}) {
  return Error(ErrorClass::bad_data, "lab.analysis.characterize: " + what, hint);
}

std::array<double, 3> triple(const json& v, const std::string& what) {
  if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number()) {
    throw bad(what + " is not three numbers: " + v.dump());
  }
  return {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
}

// The patches both sides have, in the camera's order.
ca::ChartData match(const json& camera, const json& reference, const std::vector<std::string>& exclude) {
  for (const auto* side : {&camera, &reference}) {
    if (!side->is_object() || !side->contains("ids") || !(*side)["ids"].is_array()) throw bad("camera and reference need a list ids");
  }
  if (!camera.contains("values") || camera["values"].size() != camera["ids"].size()) throw bad("the camera needs one [r, g, b] in values per id");
  if (!reference.contains("Lab") || !reference.contains("XYZ") || reference["Lab"].size() != reference["ids"].size() ||
      reference["XYZ"].size() != reference["ids"].size()) {
    throw bad("the reference needs one Lab and one XYZ per id (lab.runs.chart_reference)");
  }
  std::map<std::string, std::size_t> ref;
  for (std::size_t i = 0; i < reference["ids"].size(); ++i) ref[reference["ids"][i].get<std::string>()] = i;
  std::vector<std::size_t> cam_rows, ref_rows;
  std::string missing;
  for (std::size_t i = 0; i < camera["ids"].size(); ++i) {
    const std::string id = camera["ids"][i].get<std::string>();
    if (std::find(exclude.begin(), exclude.end(), id) != exclude.end()) continue;
    auto it = ref.find(id);
    if (it == ref.end()) {
      missing += (missing.empty() ? "" : ", ") + id;
      continue;
    }
    cam_rows.push_back(i);
    ref_rows.push_back(it->second);
  }
  if (!missing.empty()) {
    // A different chart on the table than in the cabinet is a mistake, not something to fit around.
    throw bad("the reference has no patches " + missing, "read the chart that was photographed (chart-read with the same chart)");
  }
  ca::ChartData d;
  const auto n = static_cast<Eigen::Index>(cam_rows.size());
  d.rgb.resize(n, 3);
  d.xyz.resize(n, 3);
  d.lab.resize(n, 3);
  for (Eigen::Index r = 0; r < n; ++r) {
    const std::size_t c = cam_rows[static_cast<std::size_t>(r)], f = ref_rows[static_cast<std::size_t>(r)];
    d.ids.push_back(camera["ids"][c].get<std::string>());
    auto rgb = triple(camera["values"][c], "camera value of " + d.ids.back());
    auto xyz = triple(reference["XYZ"][f], "reference XYZ of " + d.ids.back());
    auto lab = triple(reference["Lab"][f], "reference L*a*b* of " + d.ids.back());
    for (int k = 0; k < 3; ++k) {
      d.rgb(r, k) = rgb[static_cast<std::size_t>(k)];
      d.xyz(r, k) = xyz[static_cast<std::size_t>(k)];
      d.lab(r, k) = lab[static_cast<std::size_t>(k)];
    }
  }
  if (d.size() < 24) throw bad("only " + std::to_string(d.size()) + " patches match; a characterization needs at least 24");
  d.check();
  return d;
}

double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  if (v.empty()) return 0;
  const double pos = q * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const auto hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (v[hi] - v[lo]) * (pos - static_cast<double>(lo));
}

json stats_json(const ca::ErrorStats& e) {
  return json{{"mean", e.s00.mean}, {"median", e.s00.median}, {"p95", quantile(e.de00, 0.95)},
              {"max", e.s00.max},   {"mean_de76", e.s76.mean}, {"max_de76", e.s76.max}};
}

Eigen::MatrixXd lab_rows(const std::vector<ca::Lab>& lab) {
  Eigen::MatrixXd m(static_cast<Eigen::Index>(lab.size()), 3);
  for (std::size_t i = 0; i < lab.size(); ++i) {
    m(static_cast<Eigen::Index>(i), 0) = lab[i].L;
    m(static_cast<Eigen::Index>(i), 1) = lab[i].a;
    m(static_cast<Eigen::Index>(i), 2) = lab[i].b;
  }
  return m;
}

// (a) §7.1: the encoded values read in the camera's colour space. Nothing is fitted.
json camera_colour_space(const ca::ChartData& d, double full_scale, ca::RgbSpace space) {
  std::vector<ca::Rgb> rgb;
  for (Eigen::Index r = 0; r < d.rgb.rows(); ++r) rgb.push_back({d.rgb(r, 0) / full_scale, d.rgb(r, 1) / full_scale, d.rgb(r, 2) / full_scale});
  auto e = ca::evaluate(lab_rows(ca::rgb_to_lab_d50(space, rgb)), d.lab);
  json s = stats_json(e);
  return json{{"training", s}, {"cv", s}, {"fitted", false},
              {"colour_space", space == ca::RgbSpace::srgb ? "srgb" : "adobe_rgb"}};
}

// Which patches each fold holds out: every patch alone (LOO) or every k-th (k-fold, interleaved so
// each fold samples the whole chart rather than one region of it).
std::vector<std::vector<std::size_t>> folds(std::size_t n, const ca::CvSpec& cv) {
  std::vector<std::vector<std::size_t>> out;
  const std::size_t k = cv.kind == ca::CvSpec::Kind::k_fold ? static_cast<std::size_t>(std::max(2, cv.folds)) : n;
  out.resize(std::min(k, n));
  for (std::size_t i = 0; i < n; ++i) out[i % out.size()].push_back(i);
  return out;
}

// (b) §7.2: a matrix/shaper profile; cross-validated by building it again without each fold.
json icc_profile(const ca::ChartData& d, double gamma, const ca::CvSpec& cv) {
  // Profiles take device values 0–1; the brightest patch sets the unit (a unit, not a fitted value).
  const double scale = d.rgb.maxCoeff() > 0 ? d.rgb.maxCoeff() : 1;
  ca::ChartData unit = d;
  unit.rgb = d.rgb / scale;
  auto training = ca::evaluate(ca::apply_profile(ca::build_matrix_shaper_profile(unit, gamma), unit.rgb), d.lab);
  Eigen::MatrixXd predicted(d.rgb.rows(), 3);
  for (const auto& held : folds(d.size(), cv)) {
    std::vector<std::size_t> keep;
    for (std::size_t i = 0; i < d.size(); ++i) {
      if (std::find(held.begin(), held.end(), i) == held.end()) keep.push_back(i);
    }
    auto profile = ca::build_matrix_shaper_profile(unit.subset(keep), gamma);
    auto out = ca::apply_profile(profile, unit.subset(held).rgb);
    for (std::size_t j = 0; j < held.size(); ++j) predicted.row(static_cast<Eigen::Index>(held[j])) = out.row(static_cast<Eigen::Index>(j));
  }
  auto cross = ca::evaluate(predicted, d.lab);
  return json{{"training", stats_json(training)}, {"cv", stats_json(cross)}, {"fitted", true}, {"gamma", gamma},
              {"kind", "matrix/shaper"}};
}

json matrix_json(const Eigen::MatrixXd& m) {
  json out = json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) out.push_back({m(r, 0), m(r, 1), m(r, 2)});
  return out;
}

// (c) §7.3: every family and target, cross-validated; the chosen model, refitted on every patch.
json adapted_mapping(const ca::ChartData& d, const ca::CvSpec& cv, double tolerance, json& selected) {
  ca::SelectionOptions so;
  so.tolerance_de00 = tolerance;
  const std::vector<ca::FitTarget> targets{ca::FitTarget::xyz_then_lab, ca::FitTarget::lab_direct,
                                           ca::FitTarget::xyz_lightness_weighted};
  ca::Selection s = ca::select_method(ca::all_methods(), targets, d, {}, cv, so);
  const ca::FitReport& chosen = s.candidates[s.chosen];
  const ca::FitReport& best = s.candidates[s.best];
  json candidates = json::array();
  for (const auto& c : s.candidates) {
    if (c.rank_deficient) continue;
    candidates.push_back({{"method", c.method}, {"target", ca::to_string(c.target)}, {"parameters", c.parameters},
                          {"training_mean", c.training.s00.mean}, {"cv_mean", c.cv.s00.mean}});
  }
  ca::FitOptions fo;
  fo.target = chosen.target;
  ca::Characterization model = ca::fit_method(chosen.method, d, fo);
  selected = json{{"approach", "adapted_mapping"},
                  {"method", chosen.method},
                  {"target", ca::to_string(chosen.target)},
                  {"parameters", chosen.parameters},
                  {"description", model.describe()},
                  {"input_scale", model.input_scale()},
                  {"white", {d.white.X, d.white.Y, d.white.Z}}};
  if (!model.spline()) {
    auto poly = ca::fit(chosen.method, d, fo);
    json terms = json::array();
    for (const auto& t : poly.terms().terms) terms.push_back({{"label", t.label()}, {"exponent", t.exponent}});
    selected["terms"] = terms;
    selected["coefficients"] = matrix_json(poly.coefficients());  // m × 3, for rgb / input_scale
  } else {
    // A spline is its training patches plus λ: store those, and fit_method(method, data, λ) gives it back.
    selected["smoothing"] = model.spline()->smoothing();
    selected["training"] = {{"ids", d.ids}, {"rgb", matrix_json(d.rgb)}, {"XYZ", matrix_json(d.xyz)}, {"Lab", matrix_json(d.lab)}};
  }
  return json{{"training", stats_json(chosen.training)},
              {"cv", stats_json(chosen.cv)},
              {"fitted", true},
              {"method", chosen.method},
              {"target", ca::to_string(chosen.target)},
              {"best_method", best.method},
              {"best_target", ca::to_string(best.target)},
              {"best_cv_mean", best.cv.s00.mean},
              {"tolerance_de00", s.tolerance},
              {"candidates", candidates}};
}

}  // namespace

json characterize(const json& camera, const json& reference, const json& options_in) {
  const json options = options_in.is_object() ? options_in : json::object();
  std::vector<std::string> exclude;
  if (options.contains("exclude")) {
    for (const auto& id : options["exclude"]) {
      if (!id.is_string()) throw Error(ErrorClass::bad_parameter, "lab.analysis.characterize: exclude must list patch ids");
      exclude.push_back(id);
    }
  }
  const std::string format = camera.is_object() ? camera.value("format", std::string("raw")) : "raw";
  const bool raw = format == "raw";
  const int bits = camera.is_object() ? camera.value("bits", raw ? 16 : 8) : 16;
  const ca::CvSpec cv = ca::CvSpec::parse(options.value("cv", std::string("loo")));
  const double tolerance = options.value("tolerance_de00", 0.1);
  const std::string space_name = options.value("colour_space", std::string("adobe_rgb"));
  if (space_name != "adobe_rgb" && space_name != "srgb") {
    throw Error(ErrorClass::bad_parameter, "lab.analysis.characterize: colour_space must be adobe_rgb or srgb");
  }
  // The profile's tone curve: linear counts for a raw, the encoding's gamma (≈ 2.2) for a developed image.
  const double gamma = options.value("profile_gamma", raw ? 1.0 : 2.2);

  ca::ChartData d = match(camera, reference, exclude);
  json approaches = json::object();
  if (!raw) {
    approaches["camera_colour_space"] = camera_colour_space(d, std::ldexp(1.0, bits) - 1,
                                                           space_name == "srgb" ? ca::RgbSpace::srgb : ca::RgbSpace::adobe_rgb_1998);
  }
  approaches["icc_profile"] = icc_profile(d, gamma, cv);
  json selected;
  approaches["adapted_mapping"] = adapted_mapping(d, cv, tolerance, selected);
  std::string best;
  double best_cv = std::numeric_limits<double>::infinity();
  for (const auto& [name, a] : approaches.items()) {
    if (a["cv"]["mean"].get<double>() < best_cv) {
      best_cv = a["cv"]["mean"].get<double>();
      best = name;
    }
  }
  return json{{"format", format}, {"patches", d.size()}, {"cv", cv.name()}, {"approaches", approaches},
              {"best_approach", best}, {"selected", selected}, {"unit", "ΔE00"}};
}

}  // namespace colorlab::campaigns
