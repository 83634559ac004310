#include "colorlab/analysis/relighting.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <memory>

#include "colorlab/analysis/blackbox.hpp"
#include "colorlab/analysis/color_difference.hpp"
#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/analysis/standard_data.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::analysis {

namespace {

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const auto hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (v[hi] - v[lo]) * (pos - static_cast<double>(lo));
}

// The posterior's square root per channel, decomposed once for any number of draws.
class CurveSampler {
 public:
  explicit CurveSampler(const SensitivityEstimate& s) : mean_(s.curves) {
    for (std::size_t c = 0; c < 3; ++c) {
      // Eigen-decomposition rather than Cholesky: the mixture covariance is only positive semi-definite.
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(s.covariance[c]);
      vectors_[c] = eig.eigenvectors();
      root_[c] = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
    }
  }
  // One set of curves, clipped at 0 as the sensitivities are.
  Eigen::MatrixXd draw(std::mt19937& rng) const {
    std::normal_distribution<double> nd(0, 1);  // fresh per draw: a draw's stream does not depend on the one before
    Eigen::MatrixXd out = mean_;
    for (std::size_t c = 0; c < 3; ++c) {
      Eigen::VectorXd z(root_[c].size());
      for (Eigen::Index k = 0; k < z.size(); ++k) z(k) = nd(rng);
      out.row(static_cast<Eigen::Index>(c)) += (vectors_[c] * root_[c].cwiseProduct(z)).transpose();
    }
    return out.cwiseMax(0.0);
  }

 private:
  Eigen::MatrixXd mean_;
  std::array<Eigen::MatrixXd, 3> vectors_;
  std::array<Eigen::VectorXd, 3> root_;
};

}  // namespace

// The lamp-independent part of chart_under_lamp: every resampling that depends only on the grids.
struct RelightingGrids {
  Eigen::MatrixXd reflectance;  // n × fine: the reflectances at 1 nm over the curves' range (Sprague or cubic)
  Eigen::MatrixXd lamp;         // fine × the lamp's bands (linear)
  Eigen::MatrixXd curve;        // fine × the curves' bands: a curve linear between its wavelengths
  IntegratorGrids reference;    // CIE 1931 2° reference colours for any spectrum on the lamp's wavelengths

  RelightingGrids(const SpectralSet& refl, const std::vector<double>& lamp_grid, const std::vector<double>& grid)
      : reference(lamp_grid, load_observer(Observer::cie1931_2deg), refl.wavelengths) {
    const auto fine = uniform_grid(grid.front(), grid.back(), 1.0);
    reflectance = resample(refl, fine, sprague_applicable(refl.wavelengths) ? Interpolation::sprague : Interpolation::cubic_spline).values;
    lamp = resampling_matrix(lamp_grid, fine, Interpolation::linear);
    curve = resampling_matrix(grid, fine, Interpolation::linear);
  }
};

namespace {

// The chart under one lamp from grids built for the reflectances, the lamp's wavelengths and the curves' grid.
ChartUnderLamp relight(const SpectralSet& refl, const LampSpectrum& lamp, const std::vector<double>& grid,
                       std::shared_ptr<const RelightingGrids> grids) {
  const ReflectanceIntegrator integ = grids->reference.integrator(lamp.spd);  // first: it validates the spectrum
  // RAW = Σ_fine r·l·S_fine with S_fine = M · s (M: fine × bands) for a curve linear between the grid's wavelengths.
  const Eigen::MatrixXd l = lamp.spd.values * grids->lamp.transpose();
  const Eigen::RowVectorXd e = l.row(0);
  ChartUnderLamp out;
  out.lamp = lamp.name;
  out.lamp_measured = lamp.measured;
  out.lamp_warning = lamp.warning();
  out.wavelengths = grid;
  out.reflectances = refl;
  out.lamp_spd = lamp.spd;
  out.radiance = (grids->reflectance.array().rowwise() * e.array()).matrix() * grids->curve;
  out.white = e * grids->curve;

  ChartData& c = out.reference;
  c.ids = refl.names;
  c.white = kIccD50White;
  const auto xyz = integ.xyz(refl);
  c.xyz.resize(static_cast<Eigen::Index>(xyz.size()), 3);
  for (std::size_t i = 0; i < xyz.size(); ++i) {
    const Xyz a = bradford_adapt(xyz[i], integ.white(), kIccD50White);
    c.xyz.row(static_cast<Eigen::Index>(i)) << a.X, a.Y, a.Z;
  }
  c.lab = xyz_rows_to_lab(c.xyz, c.white);
  out.grids = std::move(grids);
  return out;
}

}  // namespace

std::string LampSpectrum::warning() const {
  if (measured) return {};
  return "lamp " + name + ": its spectrum is the nominal standard " + (spd.names.empty() ? std::string("?") : spd.names.front()) +
         ", not a measurement of this lamp; a real " + name +
         " differs from its standard (phosphors, age, dimming), and the characterization inherits that difference — measure the "
         "lamp's spectrum (spectroradiometer on the cabinet's white) and characterize again";
}

LampSpectrum nominal_lamp(const std::string& lamp) {
  std::string key = lamp;
  for (auto& c : key) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  // The cabinet's lamps and the CIE table each is sold as (sim/scene's lamps; colorimetry-notes §6.2).
  static const std::map<std::string, std::string, std::less<>> table{
      {"D65", "D65"},
      {"D50", "D50"},
      {"A", "A"},
      {"TL84", "F11"},
      {"840", "F11"},
      {"CWF", "F2"},
  };
  std::string standard = key;
  if (auto it = table.find(key); it != table.end()) standard = it->second;
  LampSpectrum out;
  out.name = lamp;
  try {
    out.spd = load_illuminant(standard);
  } catch (const Error& e) {
    throw Error(ErrorClass::not_found, "lamp " + lamp + " has no standard spectrum (" + e.what() + ")",
                "name one of D65, D50, A, TL84, CWF or a CIE F-series illuminant, or give the lamp's measured spectrum");
  }
  out.measured = false;
  return out;
}

LampSpectrum measured_lamp(const std::string& lamp, SpectralSet spd) {
  spd.check_shape();
  if (spd.size() != 1) throw Error(ErrorClass::bad_data, "lamp " + lamp + ": a measured spectrum is one row, not " + std::to_string(spd.size()));
  validate_emission(spd);
  if (!(spd.values.maxCoeff() > 0)) throw Error(ErrorClass::bad_data, "lamp " + lamp + ": the measured spectrum is zero everywhere");
  return {lamp, std::move(spd), true};
}

ChartUnderLamp chart_under_lamp(const SpectralSet& refl, const LampSpectrum& lamp, const std::vector<double>& grid) {
  refl.check_shape();
  lamp.spd.check_shape();
  validate_reflectance(refl, 0.02);
  if (grid.size() < 3) throw Error(ErrorClass::bad_parameter, "chart under a lamp: the sensitivities' grid needs at least 3 wavelengths");
  const double lo = grid.front(), hi = grid.back();
  for (const auto* s : {&refl, &lamp.spd})
    if (s->wavelengths.front() > lo + 1e-9 || s->wavelengths.back() < hi - 1e-9)
      throw Error(ErrorClass::bad_data, "chart under lamp " + lamp.name + ": " + s->source + " covers " +
                                            std::to_string(s->wavelengths.front()) + "–" + std::to_string(s->wavelengths.back()) +
                                            " nm, the sensitivities " + std::to_string(lo) + "–" + std::to_string(hi) + " nm");
  return relight(refl, lamp, grid, std::make_shared<const RelightingGrids>(refl, lamp.spd.wavelengths, grid));
}

ChartData ChartUnderLamp::predict(const Eigen::MatrixXd& curves) const {
  if (curves.rows() != 3 || curves.cols() != radiance.cols())
    throw Error(ErrorClass::bad_data, "chart under lamp " + lamp + ": curves are " + std::to_string(curves.rows()) + " × " +
                                          std::to_string(curves.cols()) + ", need 3 × " + std::to_string(radiance.cols()));
  const Eigen::RowVectorXd w = white * curves.transpose();
  if (!(w.minCoeff() > 0))
    throw Error(ErrorClass::bad_data, "chart under lamp " + lamp + ": a channel sees nothing of the lamp's white",
                "the lamp's spectrum and the sensitivities do not overlap");
  ChartData c = reference;
  c.rgb = (radiance * curves.transpose()).array().rowwise() / w.array();
  return c;
}

ChartUnderLamp ChartUnderLamp::under(const SpectralSet& spd) const {
  const LampSpectrum drawn{lamp, spd, lamp_measured};
  if (!grids || spd.wavelengths != lamp_spd.wavelengths) return chart_under_lamp(reflectances, drawn, wavelengths);
  return relight(reflectances, drawn, wavelengths, grids);
}

SpectralSet draw_nominal_lamp(const SpectralSet& standard, const std::vector<double>& grid, std::mt19937& rng) {
  standard.check_shape();
  if (standard.size() != 1 || grid.size() < 2 || !(grid.back() > grid.front()))
    throw Error(ErrorClass::bad_parameter, "nominal lamp draw: needs one spectrum and a grid of at least two wavelengths");
  std::normal_distribution<double> nd(0, 1);
  std::array<double, 3> a{};
  for (std::size_t k = 0; k < a.size(); ++k) a[k] = kNominalLampLogSdev[k] * nd(rng);
  SpectralSet out = standard;
  const double lo = grid.front(), hi = grid.back();
  for (std::size_t j = 0; j < out.wavelengths.size(); ++j) {
    const double x = std::clamp((2 * out.wavelengths[j] - lo - hi) / (hi - lo), -1.0, 1.0);
    const double g = a[0] * x + a[1] * (3 * x * x - 1) / 2 + a[2] * (5 * x * x * x - 3 * x) / 2;
    out.values(0, static_cast<Eigen::Index>(j)) *= std::exp(g);
  }
  return out;
}

Eigen::MatrixXd SensitivityEstimate::draw(std::mt19937& rng) const { return CurveSampler(*this).draw(rng); }

SensitivityEstimate estimate_sensitivities(const ChartUnderLamp& photographed, const Eigen::MatrixXd& raw, const SensitivityPrior& prior) {
  if (raw.rows() != photographed.radiance.rows())
    throw Error(ErrorClass::bad_data, "sensitivities: " + std::to_string(raw.rows()) + " RAW triples for " +
                                          std::to_string(photographed.radiance.rows()) + " patches");
  BlackBoxOptions o;
  o.prior = prior;
  const BlackBoxModel m = fit_blackbox(photographed.radiance, raw, o);
  return {photographed.wavelengths, m.sensitivities, m.sensitivity_covariance};
}

LampCharacterization characterize_across_lamps(const SensitivityEstimate& s, const ChartUnderLamp& target,
                                               const AcrossLampsOptions& o) {
  if (s.wavelengths != target.wavelengths)
    throw Error(ErrorClass::bad_data, "across lamps: the sensitivities and the chart under " + target.lamp + " are on different grids");
  if (o.draws < 0) throw Error(ErrorClass::bad_parameter, "across lamps: draws must be ≥ 0");
  const ChartData predicted = target.predict(s.curves);
  FitOptions fo;
  fo.input_scale = 1.0;  // white-balanced: the perfect white is 1 in every channel, under any lamp
  fo.spline_search = o.spline_search;
  const Selection sel = select_method(o.methods, o.targets, predicted, fo, o.cv);
  const FitReport& chosen = sel.candidates[sel.chosen];
  fo.target = chosen.target;
  Characterization model = fit_method(chosen.method, predicted, fo);
  // Each draw refits the chosen family at the point fit's smoothing: the draws measure what the curves' uncertainty
  // does to this model, not to a λ search (which would cost 41 fits per draw).
  auto refit = [&](const ChartData& chart) {
    if (!model.spline()) return fit_method(chosen.method, chart, fo);
    SplineOptions so = spline_options(chosen.method, fo);
    so.smoothing = model.spline()->smoothing();
    so.hat_matrix = !o.share_draw_work;
    return Characterization(fit_spline(chart, so));
  };
  // A nominal lamp's own uncertainty is drawn with the curves (its own stream: the curves' draws stay the same with
  // or without it). It moves the chart's camera values and its reference colours together, as a real lamp would.
  const bool draw_lamp = o.nominal_lamp_uncertainty && !target.lamp_measured;
  auto chart_under = [&](const SpectralSet& spd) {
    return o.share_draw_work ? target.under(spd)
                             : chart_under_lamp(target.reflectances, LampSpectrum{target.lamp, spd, target.lamp_measured}, target.wavelengths);
  };
  std::optional<CurveSampler> sampler;
  if (o.share_draw_work && o.draws > 0) sampler.emplace(s);
  std::vector<Characterization> draws;
  draws.reserve(static_cast<std::size_t>(o.draws));
  std::mt19937 rng(o.seed), lamp_rng(o.seed + 0x9e3779b9u);
  for (int d = 0; d < o.draws; ++d) {
    const Eigen::MatrixXd curves = sampler ? sampler->draw(rng) : s.draw(rng);
    draws.push_back(refit(draw_lamp ? chart_under(draw_nominal_lamp(target.lamp_spd, target.wavelengths, lamp_rng)).predict(curves)
                                    : target.predict(curves)));
  }

  LampCharacterization out{.lamp = target.lamp,
                           .lamp_measured = target.lamp_measured,
                           .warnings = {},
                           .method = "across-lamps:" + target.lamp + ":" + chosen.method,
                           .family = chosen.method,
                           .target = chosen.target,
                           .parameters = chosen.parameters,
                           .cv = chosen.cv,
                           .model = std::move(model),
                           .draws = std::move(draws),
                           .misfit95 = quantile(chosen.cv.de00, 0.95)};
  if (!target.lamp_warning.empty()) out.warnings.push_back(target.lamp_warning);
  return out;
}

Eigen::VectorXd LampCharacterization::uncertainty95(const Eigen::MatrixXd& rgb) const {
  const Eigen::MatrixXd centre = model.apply(rgb);
  std::vector<Eigen::MatrixXd> drawn;
  drawn.reserve(draws.size());
  for (const auto& d : draws) drawn.push_back(d.apply(rgb));
  Eigen::VectorXd out(rgb.rows());
  for (Eigen::Index i = 0; i < rgb.rows(); ++i) {
    std::vector<double> de;
    const Lab c{centre(i, 0), centre(i, 1), centre(i, 2)};
    for (const auto& m : drawn) de.push_back(delta_e2000(c, Lab{m(i, 0), m(i, 1), m(i, 2)}));
    const double spread = quantile(de, 0.95);
    out(i) = std::hypot(spread, misfit95);
  }
  return out;
}

}  // namespace colorlab::analysis
