#include "sensitivities.hpp"

#include <cmath>

#include "colorlab/analysis/spectral.hpp"
#include "colorlab/core/data_paths.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::sim::camera::detail {
namespace {

constexpr double grid_start = 380.0, grid_step = 5.0;
constexpr std::size_t grid_size = 71;

Sensitivities from_file(const std::filesystem::path& path) {
  const auto set = analysis::read_spectra(path);
  Sensitivities out;
  out.source = path.string();
  const char* names[] = {"R", "G", "B"};
  // Resample inside the file's range; the sensor is taken as blind outside it (the IR/UV filters).
  const double lo = set.wavelengths.front(), hi = set.wavelengths.back();
  std::vector<double> inside;
  for (std::size_t i = 0; i < grid_size; ++i) {
    const double nm = grid_start + grid_step * double(i);
    if (nm >= lo - 1e-9 && nm <= hi + 1e-9) inside.push_back(nm);
  }
  if (inside.size() < 10) throw Error(ErrorClass::bad_data, path.string() + ": sensitivities do not cover 380–730 nm");
  const auto resampled = analysis::resample(set, inside, analysis::Interpolation::cubic_spline);
  for (int c = 0; c < 3; ++c) {
    const std::size_t row = set.require(names[c]);
    Spectrum s{grid_start, grid_step, std::vector<double>(grid_size, 0.0)};
    for (std::size_t k = 0; k < inside.size(); ++k) {
      const auto i = static_cast<std::size_t>(std::lround((inside[k] - grid_start) / grid_step));
      s.values[i] = std::max(0.0, resampled.values(static_cast<Eigen::Index>(row), static_cast<Eigen::Index>(k)));
    }
    out.rgb[static_cast<std::size_t>(c)] = std::move(s);
  }
  return out;
}

// Gaussian-ish silicon-behind-dyes curves with the secondary lobes real Bayer filters have.
Sensitivities parametric() {
  Sensitivities out;
  out.source = "parametric";
  struct Lobe {
    double centre, width, weight;
  };
  const std::array<std::array<Lobe, 2>, 3> lobes{{
      {{{600, 38, 1.0}, {450, 25, 0.04}}},
      {{{535, 42, 1.0}, {610, 30, 0.08}}},
      {{{460, 30, 1.0}, {530, 30, 0.10}}},
  }};
  for (std::size_t c = 0; c < 3; ++c) {
    Spectrum s{grid_start, grid_step, std::vector<double>(grid_size)};
    for (std::size_t i = 0; i < grid_size; ++i) {
      const double nm = s.wavelength(i);
      double v = 0;
      for (const auto& l : lobes[c]) v += l.weight * std::exp(-0.5 * std::pow((nm - l.centre) / l.width, 2));
      s.values[i] = v * (nm > 680 ? std::exp(-(nm - 680) / 15.0) : 1.0);  // IR-cut filter
    }
    out.rgb[c] = std::move(s);
  }
  return out;
}

}  // namespace

Sensitivities load_sensitivities(const CameraConfig& config, const Scene& scene) {
  Sensitivities s;
  if (config.force_parametric_sensitivities) {
    s = parametric();
  } else if (config.sensitivity_file) {
    s = from_file(*config.sensitivity_file);
  } else if (auto shared = paths::shared_data_file("camera_ssf_canon_eos_20d_camspec_10nm_400_720.csv")) {
    s = from_file(*shared);
  } else {
    s = parametric();
  }
  // Normalise: green response to a D65-lit grey floor of 1 cd/m² becomes 1.
  const Spectrum grey{380.0, 350.0, {Scene::floor_reflectance(), Scene::floor_reflectance()}};
  const Spectrum radiance = scene.lamp_radiance_per_cd(Lamp::d65, grey);
  double g = 0;
  for (std::size_t i = 0; i < radiance.values.size(); ++i) g += radiance.values[i] * s.rgb[1].at(radiance.wavelength(i));
  g *= 683.0 * radiance.step_nm;
  if (!(g > 0)) throw Error(ErrorClass::bad_data, s.source + ": green sensitivity is zero");
  for (auto& ch : s.rgb)
    for (double& v : ch.values) v /= g;
  return s;
}

}  // namespace colorlab::sim::camera::detail
