#include "colorlab/campaigns/characterize.hpp"
#include "colorlab/campaigns/characterize_lamps.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <string_view>

#include "colorlab/analysis/blackbox.hpp"
#include "colorlab/analysis/characterization.hpp"
#include "colorlab/analysis/icc_profile.hpp"
#include "colorlab/analysis/rgb_spaces.hpp"
#include "colorlab/analysis/standard_data.hpp"
#include "colorlab/core/data_paths.hpp"
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
  return json{
      {"mean", e.s00.mean},
      {"median", e.s00.median},
      {"p95", quantile(e.de00, 0.95)},
      {"max", e.s00.max},
      {"mean_de76", e.s76.mean},
      {"max_de76", e.s76.max},
  };
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
  return json{
      {"training", s},
      {"cv", s},
      {"fitted", false},
      {"colour_space", space == ca::RgbSpace::srgb ? "srgb" : "adobe_rgb"},
  };
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
  return json{
      {"training", stats_json(training)},
      {"cv", stats_json(cross)},
      {"fitted", true},
      {"gamma", gamma},
      {"kind", "matrix/shaper"},
  };
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
    candidates.push_back({
        {"method", c.method},
        {"target", ca::to_string(c.target)},
        {"parameters", c.parameters},
        {"training_mean", c.training.s00.mean},
        {"cv_mean", c.cv.s00.mean},
    });
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

// (d) §7.4: the camera as a black box. Spectral sensitivities s_c ≥ 0 are fitted so that
// RAW_c = Σ s_c(λ) · reflectance(λ) · lamp(λ) reproduces the raw counts (analysis/blackbox.hpp: NNLS
// under a prior learned from other cameras' measured curves when the shared data set has them, else
// a second-difference penalty chosen by GCV). The dissertation compares the predicted counts with the
// photograph's (Table 13); to set it beside the other approaches in ΔE00 the predicted counts go
// through the raw's own mapping to L*a*b* (§7.3's selected method), fitted, like the sensitivities,
// without the patches each fold holds out.

// The CIE illuminant a cabinet lamp's spectrum is taken to be: the tables the simulated lab lights
// its scene with (sim/scene lamps.cpp), from colord-data.
std::optional<std::string> illuminant_of_lamp(std::string lamp) {
  for (auto& c : lamp) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  static const std::map<std::string, std::string, std::less<>> table{
      {"D65", "D65"}, {"D50", "D50"}, {"A", "A"}, {"TL84", "F11"}, {"F11", "F11"}, {"840", "F11"}, {"CWF", "F2"}, {"F2", "F2"}};
  auto it = table.find(lamp);
  if (it == table.end()) return std::nullopt;
  return it->second;
}

// What the black box is fitted from; `missing` says why it cannot be, when it cannot.
struct BlackBoxSetup {
  std::string missing;
  std::string lamp, illuminant, spd_source;
  std::vector<double> wavelengths;
  Eigen::MatrixXd radiance;  // n × bands in d's patch order: reflectance × the lamp's weight per band
  std::optional<ca::SensitivityPrior> prior;
  std::string prior_source;
  std::vector<std::string> prior_excluded;
};

// The lamp's weight per band of the chart's grid: its SPD on its own (finer) grid, each sample
// shared between the two neighbouring bands as linear interpolation of the reflectance shares it
// (the adjoint of interpolating the reflectance onto the lamp's grid), so a fluorescent tube's
// mercury lines between two 10 nm bands count in both. Peak 1 (the sensitivities absorb the scale).
Eigen::RowVectorXd lamp_weights(const ca::SpectralSet& lamp, const std::vector<double>& grid) {
  std::vector<double> inside;
  std::vector<Eigen::Index> cols;
  for (std::size_t k = 0; k < lamp.bands(); ++k) {
    if (lamp.wavelengths[k] >= grid.front() - 1e-9 && lamp.wavelengths[k] <= grid.back() + 1e-9) {
      inside.push_back(lamp.wavelengths[k]);
      cols.push_back(static_cast<Eigen::Index>(k));
    }
  }
  if (inside.size() < grid.size()) {
    throw bad(lamp.names.front() + " does not cover the chart's spectra (" + std::to_string(grid.front()) + "–" +
              std::to_string(grid.back()) + " nm) finely enough");
  }
  Eigen::VectorXd spd(static_cast<Eigen::Index>(inside.size()));
  for (std::size_t j = 0; j < cols.size(); ++j) spd(static_cast<Eigen::Index>(j)) = lamp.values(0, cols[j]);
  const Eigen::MatrixXd r = ca::resampling_matrix(grid, inside, ca::Interpolation::linear);
  Eigen::RowVectorXd w = (r.transpose() * spd).transpose();
  if (!(w.maxCoeff() > 0)) throw bad(lamp.names.front() + " is dark over the chart's spectra");
  return w / w.maxCoeff();
}

BlackBoxSetup black_box_setup(const ca::ChartData& d, const json& camera, const json& reference, const json& options) {
  BlackBoxSetup s;
  const std::string format = camera.value("format", std::string("raw"));
  if (format != "raw") {
    s.missing = "the black box is fitted to linear counts: the raw only, not " + format;
    return s;
  }
  if (!reference.contains("spectra") || !reference.contains("wavelengths") || reference["spectra"].size() != reference["ids"].size()) {
    s.missing = "the reference has no spectra (a chart-read run stored before spectra were returned): run chart-read again";
    return s;
  }
  s.lamp = options.value("lamp", std::string());
  if (options.contains("illuminant") && options["illuminant"].is_string()) {
    s.illuminant = options["illuminant"].get<std::string>();
  } else if (auto il = illuminant_of_lamp(s.lamp)) {
    s.illuminant = *il;
  } else {
    s.missing = s.lamp.empty() ? "no lamp named: the black box needs the light's spectrum (give lamp or illuminant)"
                               : "no standard spectrum for lamp " + s.lamp + " (D65, A, TL84 = F11, CWF = F2): give illuminant";
    return s;
  }
  const ca::SpectralSet spd = ca::load_illuminant(s.illuminant);
  s.spd_source = spd.names.front() + " (" + spd.source + ")";

  std::vector<double> grid = reference["wavelengths"].get<std::vector<double>>();
  // The prior's curves span less than the chart's spectra (camspec: 400–720 nm); the fit uses the bands both have.
  const std::string prior = options.value("prior", std::string("camspec"));
  if (prior != "camspec" && prior != "none") throw Error(ErrorClass::bad_parameter, "lab.analysis.characterize: prior must be camspec or none");
  std::optional<ca::SpectralSet> curves;
  if (prior == "camspec") {
    if (auto file = paths::shared_data_file("camera_ssf_camspec_jiang2013_28cams_10nm_400_720.csv")) {
      curves = ca::read_spectra(*file);
      s.prior_source = file->string();
    }
  }
  std::vector<std::size_t> bands;
  for (std::size_t k = 0; k < grid.size(); ++k) {
    if (!curves || (grid[k] >= curves->wavelengths.front() - 1e-9 && grid[k] <= curves->wavelengths.back() + 1e-9)) bands.push_back(k);
  }
  for (auto k : bands) s.wavelengths.push_back(grid[k]);
  if (s.wavelengths.size() < 3) throw bad("the reference's spectra and the prior's curves share fewer than 3 wavelengths");
  if (curves) {
    // An empty Lua table arrives as an object.
    if (options.contains("prior_exclude") && options["prior_exclude"].is_array()) {
      for (const auto& name : options["prior_exclude"]) {
        if (!name.is_string()) throw Error(ErrorClass::bad_parameter, "lab.analysis.characterize: prior_exclude must list camera names");
        s.prior_excluded.push_back(name);
      }
    }
    s.prior = ca::learn_sensitivity_prior(*curves, s.wavelengths, s.prior_excluded);
  }

  const Eigen::RowVectorXd lamp = lamp_weights(spd, grid);
  std::map<std::string, std::size_t> row;
  for (std::size_t i = 0; i < reference["ids"].size(); ++i) row[reference["ids"][i].get<std::string>()] = i;
  s.radiance.resize(static_cast<Eigen::Index>(d.size()), static_cast<Eigen::Index>(bands.size()));
  for (std::size_t i = 0; i < d.size(); ++i) {
    const json& values = reference["spectra"][row.at(d.ids[i])];
    if (values.size() != grid.size()) throw bad("the reference spectrum of " + d.ids[i] + " has " + std::to_string(values.size()) + " bands, not " + std::to_string(grid.size()));
    for (std::size_t j = 0; j < bands.size(); ++j) {
      const double v = values[bands[j]].get<double>();
      // A reflectance reads a little below 0 in the noise of a black patch; the model's light is never negative.
      s.radiance(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = std::max(0.0, v) * lamp(static_cast<Eigen::Index>(bands[j]));
    }
  }
  return s;
}

// Table 13: |predicted − measured| per channel (min, median, mean, max, stdev), in counts and in % of the raw's full
// scale.
json residual_table(const Eigen::MatrixXd& residuals, double full_scale) {
  json out = json::object();
  for (int c = 0; c < 3; ++c) {
    std::vector<double> a;
    for (Eigen::Index i = 0; i < residuals.rows(); ++i) a.push_back(std::abs(residuals(i, c)));
    const ca::Summary sum = ca::summarize(a);
    out[std::string(1, "RGB"[c])] = {
        {"min", sum.min},
        {"mean", sum.mean},
        {"median", sum.median},
        {"max", sum.max},
        {"stdev", sum.stdev},
        {"min_pct", 100 * sum.min / full_scale},
        {"mean_pct", 100 * sum.mean / full_scale},
        {"max_pct", 100 * sum.max / full_scale},
    };
  }
  return out;
}

// Each patch's signed residual (predicted − measured, counts) per channel, in the chart's patch order: Table 13's
// statistics can be recomputed from them and a patch's misfit found (140 × 3 numbers per set).
json residual_patches(const std::vector<std::string>& ids, const Eigen::MatrixXd& residuals) {
  json out{{"ids", ids}};
  for (int c = 0; c < 3; ++c) {
    std::vector<double> v(static_cast<std::size_t>(residuals.rows()));
    for (Eigen::Index i = 0; i < residuals.rows(); ++i) v[static_cast<std::size_t>(i)] = residuals(i, c);
    out[std::string(1, "RGB"[c])] = std::move(v);
  }
  return out;
}

Eigen::MatrixXd rows_of(const Eigen::MatrixXd& m, const std::vector<std::size_t>& rows) {
  Eigen::MatrixXd out(static_cast<Eigen::Index>(rows.size()), m.cols());
  for (std::size_t j = 0; j < rows.size(); ++j) out.row(static_cast<Eigen::Index>(j)) = m.row(static_cast<Eigen::Index>(rows[j]));
  return out;
}

ca::FitTarget target_from_string(const std::string& name) {
  for (auto t : {ca::FitTarget::xyz_then_lab, ca::FitTarget::lab_direct, ca::FitTarget::xyz_lightness_weighted}) {
    if (name == ca::to_string(t)) return t;
  }
  throw Error(ErrorClass::bad_parameter, "lab.analysis.characterize: unknown mapping target " + name);
}

json black_box(const ca::ChartData& d, const BlackBoxSetup& s, const std::string& method, ca::FitTarget target,
               const ca::CvSpec& cv, double full_scale) {
  ca::BlackBoxOptions bo;
  bo.full_scale = full_scale;
  bo.prior = s.prior;
  ca::FitOptions fo;
  fo.target = target;
  const ca::BlackBoxModel model = ca::fit_blackbox(s.radiance, d.rgb, bo);
  const Eigen::MatrixXd predicted = model.predict(s.radiance);
  const ca::Characterization mapping = ca::fit_method(method, d, fo);
  const auto training = ca::evaluate(mapping.apply(predicted), d.lab);
  // A fold's mapping: the method refitted without the fold; a spline at the λ chosen on every patch,
  // as the adapted mapping's own leave-one-out does (spline_report), and not searched again per fold
  // (a λ search per patch costs a hundred times the fit).
  auto refit_mapping = [&](const ca::ChartData& train) {
    if (!mapping.spline()) return ca::fit_method(method, train, fo);
    ca::SplineOptions so = ca::spline_options(method, fo);
    so.smoothing = mapping.spline()->smoothing();
    return ca::Characterization(ca::fit_spline(train, so));
  };

  Eigen::MatrixXd held_counts(d.rgb.rows(), 3), held_lab(d.rgb.rows(), 3);
  for (const auto& held : folds(d.size(), cv)) {
    std::vector<std::size_t> keep;
    for (std::size_t i = 0; i < d.size(); ++i) {
      if (std::find(held.begin(), held.end(), i) == held.end()) keep.push_back(i);
    }
    const Eigen::MatrixXd counts = ca::fit_blackbox(rows_of(s.radiance, keep), rows_of(d.rgb, keep), bo).predict(rows_of(s.radiance, held));
    const Eigen::MatrixXd lab = refit_mapping(d.subset(keep)).apply(counts);
    for (std::size_t j = 0; j < held.size(); ++j) {
      held_counts.row(static_cast<Eigen::Index>(held[j])) = counts.row(static_cast<Eigen::Index>(j));
      held_lab.row(static_cast<Eigen::Index>(held[j])) = lab.row(static_cast<Eigen::Index>(j));
    }
  }
  const auto cross = ca::evaluate(held_lab, d.lab);

  // The curves as published ones are given: relative, the green peak 1.
  const double peak = model.sensitivities.row(1).maxCoeff() > 0 ? model.sensitivities.row(1).maxCoeff() : 1;
  json curves{{"wavelengths", s.wavelengths}, {"normalised_to", "green peak = 1"}};
  for (int c = 0; c < 3; ++c) {
    const Eigen::VectorXd curve = model.sensitivities.row(c).transpose() / peak;
    const std::string name(1, "RGB"[c]);
    curves[name] = std::vector<double>(curve.data(), curve.data() + curve.size());
    if (model.with_prior) {
      // The 95 % credible band (docs/ACCURACY.md §3: calibrated pooled over cameras, not per curve).
      const auto band = ca::credible_band(curve, model.sensitivity_sdev.row(c).transpose() / peak);
      curves[name + "_low"] = std::vector<double>(band.lower.data(), band.lower.data() + band.lower.size());
      curves[name + "_high"] = std::vector<double>(band.upper.data(), band.upper.data() + band.upper.size());
    }
  }
  json regularisation = model.with_prior
                            ? json{
                                  {"kind", "prior from other cameras' measured curves"},
                                  {"source", s.prior_source},
                                  {"cameras", s.prior->cameras},
                                  {"excluded", s.prior_excluded},
                                  {"lambda", model.lambda},
                              }
                            : json{{"kind", "second-difference smoothness, weight by GCV"}, {"lambda", model.lambda}};
  return json{{"training", stats_json(training)},
              {"cv", stats_json(cross)},
              {"fitted", true},
              {"kind", "spectral sensitivities (NNLS) → counts → the raw's mapping → L*a*b*"},
              {"lamp", s.lamp},
              {"illuminant", s.illuminant},
              {"spd", s.spd_source},
              {"spd_note", "the lamp's spectrum is assumed to be the standard illuminant's, not measured"},
              {"mapping", {{"method", method}, {"target", ca::to_string(target)}}},
              {"full_scale", full_scale},
              {"residuals", {
                                {"unit", "counts"},
                                {"training", residual_table(predicted - d.rgb, full_scale)},
                                {"cv", residual_table(held_counts - d.rgb, full_scale)},
                                {"patches", {
                                                {"training", residual_patches(d.ids, predicted - d.rgb)},
                                                {"cv", residual_patches(d.ids, held_counts - d.rgb)},
                                            }},
                            }},
              {"regularisation", regularisation},
              {"sensitivities", curves}};
}

int camera_bits(const json& camera) {
  const bool raw = camera.value("format", std::string("raw")) == "raw";
  return camera.value("bits", raw ? 16 : 8);
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
  const int bits = camera.is_object() ? camera_bits(camera) : 16;
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
  json not_fitted = json::object();
  const BlackBoxSetup setup = black_box_setup(d, camera, reference, options);
  if (setup.missing.empty()) {
    approaches["black_box"] = black_box(d, setup, selected["method"], target_from_string(selected["target"]), cv,
                                        std::ldexp(1.0, bits) - 1);
  } else if (raw) {
    not_fitted["black_box"] = setup.missing;
  }
  json across_lamps = json::object();
  if (raw && options.contains("target_lamps")) across_lamps = characterize_across_lamps(d, reference, options);  // issue 26
  std::string best;
  double best_cv = std::numeric_limits<double>::infinity();
  for (const auto& [name, a] : approaches.items()) {
    if (a["cv"]["mean"].get<double>() < best_cv) {
      best_cv = a["cv"]["mean"].get<double>();
      best = name;
    }
  }
  return json{
      {"format", format},
      {"patches", d.size()},
      {"cv", cv.name()},
      {"approaches", approaches},
      {"best_approach", best},
      {"selected", selected},
      {"not_fitted", not_fitted},
      {"unit", "ΔE00"},
      {"across_lamps", across_lamps},
  };
}

json characterize_black_box(const json& camera, const json& reference, const json& options) {
  if (!options.is_object() || !options.contains("mapping")) {
    throw Error(ErrorClass::bad_parameter, "characterize_black_box: options need mapping = {method, target}");
  }
  const ca::ChartData d = match(camera, reference, {});
  const BlackBoxSetup setup = black_box_setup(d, camera, reference, options);
  if (!setup.missing.empty()) throw Error(ErrorClass::bad_parameter, "characterize_black_box: " + setup.missing);
  return black_box(d, setup, options["mapping"]["method"], target_from_string(options["mapping"]["target"]),
                   ca::CvSpec::parse(options.value("cv", std::string("loo"))), std::ldexp(1.0, camera_bits(camera)) - 1);
}

}  // namespace colorlab::campaigns
