#include "measurement.hpp"

#include <numbers>
#include <random>

#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/sim/scene.hpp"
#include "spectrolino_model_impl.hpp"

namespace colorlab::sim {

namespace spectrolino_detail {

sp::Spectrum to_bands(const Spectrum& s) {
  Spectrum r = s.resampled(sp::kFirstWavelength, sp::kWavelengthStep, sp::kSpectrumBands);
  sp::Spectrum out{};
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = static_cast<float>(r.values[i]);
  return out;
}

Spectrum from_bands(const sp::Spectrum& b) {
  Spectrum s{static_cast<double>(sp::kFirstWavelength), static_cast<double>(sp::kWavelengthStep),
             std::vector<double>(b.begin(), b.end())};
  return s;
}

sp::Spectrum flat(float v) {
  sp::Spectrum s{};
  s.fill(v);
  return s;
}

std::vector<double> band_grid() {
  return analysis::uniform_grid(sp::kFirstWavelength,
                                sp::kFirstWavelength + sp::kWavelengthStep * (sp::kSpectrumBands - 1),
                                sp::kWavelengthStep);
}

}  // namespace spectrolino_detail

namespace sp = wire::spectrolino;
using namespace spectrolino_detail;

sp::Spectrum SpectrolinoModel::Impl::target_spectrum() const {
  if (settings.mode == sp::ctt::ModeEmission) {
    Spectrum w = scene.white_radiance(config.emission_x_mm, config.emission_y_mm);
    // Irradiance on a Lambertian white is pi x its radiance; the Spectrolino reports mW/nm/m^2.
    for (double& v : w.values) v *= std::numbers::pi * 1000.0;
    return to_bands(w);
  }
  if (settings.mode == sp::ctt::ModeTransmission) return to_bands(scene.transmission_sample());
  if (config.table && !table.head_down) return flat(static_cast<float>(kAirReflectance));
  return surface_reflectance();
}

sp::Spectrum SpectrolinoModel::Impl::surface_reflectance() const {
  if (table.on_tile(config)) return to_bands(scene.white_tile());
  auto [x, y] = table.head_mm();
  double cx = x - config.chart_origin_x_mm, cy = y - config.chart_origin_y_mm;
  if (cx >= 0 && cy >= 0 && cx <= chart_width_mm && cy <= chart_height_mm) {
    const auto& chart = scene.chart();
    if (auto i = chart.patch_at(cx, cy)) return to_bands(chart.patches[static_cast<std::size_t>(*i)].reflectance);
    return flat(static_cast<float>(config.chart_border_reflectance));
  }
  return flat(static_cast<float>(config.table_surface_reflectance));
}

sp::Spectrum SpectrolinoModel::Impl::raw_under_head() {
  sp::Spectrum truth = target_spectrum();
  if (settings.mode == sp::ctt::ModeEmission) {
    std::normal_distribution<double> n(0.0, 0.002);
    double g = 1.0 + n(rng);
    for (auto& v : truth) v = static_cast<float>(v * g);
    return truth;
  }
  return to_bands(scene.noisy_reflectance(from_bands(truth), rng));
}

std::uint8_t SpectrolinoModel::Impl::measure(double& seconds) {
  seconds = timing.measure_s;
  if (auto e = errors.take_forced()) return *e;
  if (settings.mode == sp::ctt::ModeEmission) {
    if (!cal.emission_calibrated()) return sp::exec_err::NoValidMeas;
    last.spectrum = raw_under_head();
  } else {
    if (!calibration_valid()) return sp::exec_err::NoValidMeas;
    sp::Spectrum raw = raw_under_head();
    cal.apply(raw);
    last.spectrum = raw;
  }
  last.mode = settings.mode;
  errors.new_measurement = sp::NewMeasurement::Measurement;
  ++last.count;
  return sp::exec_err::NoError;
}

}  // namespace colorlab::sim
