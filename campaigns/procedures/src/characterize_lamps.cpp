#include "colorlab/campaigns/characterize_lamps.hpp"

#include <algorithm>
#include <map>

#include "colorlab/analysis/relighting.hpp"
#include "colorlab/core/data_paths.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::campaigns {

using nlohmann::json;
namespace ca = analysis;

namespace {

Error bad(const std::string& what, const std::string& hint = {}) {
  return Error(ErrorClass::bad_parameter, "lab.analysis.characterize target_lamps: " + what, hint);
}

ca::LampSpectrum lamp_spectrum(const std::string& lamp, const json& options) {
  if (options.contains("lamp_spectra") && options["lamp_spectra"].is_object() && options["lamp_spectra"].contains(lamp)) {
    const json& s = options["lamp_spectra"][lamp];
    if (!s.is_object() || !s.contains("wavelengths") || !s.contains("values"))
      throw bad("lamp_spectra." + lamp + " needs wavelengths and values", "give the measured spectrum as {wavelengths = {...}, values = {...}}");
    ca::SpectralSet spd;
    spd.wavelengths = s["wavelengths"].get<std::vector<double>>();
    const auto v = s["values"].get<std::vector<double>>();
    if (v.size() != spd.wavelengths.size()) throw bad("lamp_spectra." + lamp + ": " + std::to_string(v.size()) + " values for " +
                                                      std::to_string(spd.wavelengths.size()) + " wavelengths");
    spd.values = Eigen::Map<const Eigen::RowVectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
    spd.names = {lamp + " (measured)"};
    spd.source = "lamp_spectra." + lamp;
    return ca::measured_lamp(lamp, std::move(spd));
  }
  return ca::nominal_lamp(lamp);
}

json matrix_json(const Eigen::MatrixXd& m) {
  json out = json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) out.push_back({m(r, 0), m(r, 1), m(r, 2)});
  return out;
}

}  // namespace

json characterize_across_lamps(const ca::ChartData& d, const json& reference, const json& options) {
  json out = json::object();
  if (!options.contains("target_lamps") || !options["target_lamps"].is_array() || options["target_lamps"].empty()) return out;
  const std::string photographed = options.value("lamp", std::string());
  if (photographed.empty()) throw bad("the photographed lamp is not named (lamp)", "give lamp, the cabinet lamp of the photograph");
  if (!reference.contains("spectra") || !reference.contains("wavelengths"))
    throw bad("the reference has no spectra", "run chart-read again: the sensitivities are estimated from the chart's spectra");
  const auto file = paths::shared_data_file("camera_ssf_camspec_jiang2013_28cams_10nm_400_720.csv");
  if (!file) throw bad("no sensitivity prior (camspec curves in the shared data set)", "install the shared data set");
  const ca::SpectralSet curves = ca::read_spectra(*file);
  std::vector<std::string> exclude;
  if (options.contains("prior_exclude") && options["prior_exclude"].is_array())
    for (const auto& n : options["prior_exclude"]) exclude.push_back(n.get<std::string>());

  // The chart's reflectances in d's patch order (a black patch may read a little below 0: clipped, as in the black box).
  std::map<std::string, std::size_t> row;
  for (std::size_t i = 0; i < reference["ids"].size(); ++i) row[reference["ids"][i].get<std::string>()] = i;
  ca::SpectralSet refl;
  refl.wavelengths = reference["wavelengths"].get<std::vector<double>>();
  refl.values.resize(static_cast<Eigen::Index>(d.size()), static_cast<Eigen::Index>(refl.wavelengths.size()));
  refl.source = "the chart-read reference";
  for (std::size_t i = 0; i < d.size(); ++i) {
    const auto v = reference["spectra"][row.at(d.ids[i])].get<std::vector<double>>();
    if (v.size() != refl.wavelengths.size()) throw bad("the reference spectrum of " + d.ids[i] + " has the wrong length");
    for (std::size_t k = 0; k < v.size(); ++k)
      refl.values(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(k)) = std::max(0.0, v[k]);
    refl.names.push_back(d.ids[i]);
  }
  std::vector<double> grid;
  for (double w : curves.wavelengths)
    if (w >= refl.wavelengths.front() - 1e-9 && w <= refl.wavelengths.back() + 1e-9) grid.push_back(w);

  const ca::SensitivityPrior prior = ca::learn_sensitivity_prior(curves, grid, exclude);
  const ca::SensitivityEstimate est =
      ca::estimate_sensitivities(ca::chart_under_lamp(refl, lamp_spectrum(photographed, options), grid), d.rgb, prior);
  ca::AcrossLampsOptions o;
  o.draws = options.value("draws", 40);
  for (const auto& name : options["target_lamps"]) {
    if (!name.is_string()) throw bad("target_lamps must list lamp names");
    const std::string lamp = name.get<std::string>();
    if (lamp == photographed) continue;  // the photograph's own lamp: the adapted mapping is that characterization
    const ca::ChartUnderLamp target = ca::chart_under_lamp(refl, lamp_spectrum(lamp, options), grid);
    const ca::LampCharacterization c = ca::characterize_across_lamps(est, target, o);
    const ca::ChartData predicted = target.predict(est.curves);
    const Eigen::VectorXd band = c.uncertainty95(predicted.rgb);
    json model{{"method", c.family}, {"target", ca::to_string(c.target)}, {"description", c.model.describe()}, {"input_scale", 1.0}};
    // As the adapted mapping stores a spline: its training patches (here, the predicted chart) and λ.
    if (const auto* s = c.model.spline()) {
      model["smoothing"] = s->smoothing();
      model["training"] = {{"ids", predicted.ids}, {"rgb", matrix_json(predicted.rgb)}, {"XYZ", matrix_json(predicted.xyz)}};
    } else {
      ca::FitOptions fo;
      fo.target = c.target;
      fo.input_scale = 1.0;
      model["coefficients"] = matrix_json(ca::fit(c.family, predicted, fo).coefficients());
    }
    out[lamp] = json{{"lamp", lamp},
                     {"lamp_measured", c.lamp_measured},
                     {"warnings", c.warnings},
                     {"method", c.method},
                     {"family", c.family},
                     {"target", ca::to_string(c.target)},
                     {"parameters", c.parameters},
                     {"cv", {{"mean", c.cv.s00.mean}, {"max", c.cv.s00.max}, {"p95", c.misfit95}}},
                     {"uncertainty95", {{"ids", predicted.ids}, {"de00", std::vector<double>(band.data(), band.data() + band.size())}}},
                     {"input", "camera RAW under " + lamp + " ÷ the RAW of a perfect white under " + lamp},
                     {"model", model}};
  }
  return out;
}

}  // namespace colorlab::campaigns
