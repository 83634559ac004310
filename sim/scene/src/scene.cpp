#include "colorlab/sim/scene.hpp"

#include <cmath>
#include <limits>
#include <mutex>
#include <string>

#include "chart.hpp"
#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/core/error.hpp"
#include "lamps.hpp"
#include "luminance_field.hpp"

namespace colorlab::sim {
namespace {

constexpr double radiance_start_nm = 380.0, radiance_step_nm = 5.0;
constexpr std::size_t radiance_samples = 71;     // 380..730
constexpr double max_luminous_efficacy = 683.0;  // lm/W

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

std::uint64_t fnv1a(std::string_view s) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (unsigned char c : s) h = (h ^ c) * 0x100000001b3ull;
  return h;
}

std::size_t index(Lamp l) { return static_cast<std::size_t>(l); }

Spectrum white_tile_spectrum() {
  // A pressed-ceramic white: ~87 % flat with the usual drop in the deep blue.
  Spectrum s{380.0, 10.0, std::vector<double>(36)};
  for (std::size_t i = 0; i < s.values.size(); ++i) {
    const double nm = s.wavelength(i);
    s.values[i] = 0.865 + 0.015 * (nm - 380.0) / 350.0 - 0.06 * std::exp(-(nm - 380.0) / 25.0);
  }
  return s;
}

Spectrum transmission_filter_spectrum() {
  // An orange gel: blocks the blue, passes the red, with a little leakage.
  Spectrum s{380.0, 10.0, std::vector<double>(36)};
  for (std::size_t i = 0; i < s.values.size(); ++i) {
    const double nm = s.wavelength(i);
    s.values[i] = 0.03 + 0.82 / (1.0 + std::exp(-(nm - 565.0) / 14.0));
  }
  return s;
}

Spectrum flat(double r) { return Spectrum{380.0, 10.0, std::vector<double>(36, r)}; }

}  // namespace

struct Scene::Impl {
  Spectrum chart_surround = flat(0.05);
  Spectrum table_plate = flat(0.80);
  SceneConfig config;
  std::shared_ptr<const SimClock> clock;
  Chart chart;
  Spectrum white_tile = white_tile_spectrum();
  Spectrum transmission = transmission_filter_spectrum();
  std::array<Spectrum, 5> lamp_spd;      // native grids
  std::array<Spectrum, 5> lamp_on_grid;  // 380..730/5 nm
  std::array<double, 5> lamp_y{};        // Σ S ȳ Δλ
  std::vector<detail::LuminanceField> fields;

  mutable std::mutex mutex;
  std::array<bool, 5> on{};
  std::array<double, 5> switched_on_at{};
  std::array<LampDrift, 5> drift{};
  double dimmer = 100.0;
  std::uint64_t version = 0;

  double warmup_locked(Lamp l, double now) const {
    const std::size_t i = index(l);
    if (!on[i]) return 1.0;
    const bool tungsten = l == Lamp::a;
    const double start = tungsten ? 0.97 : config.warmup_start_fraction;
    const double tau = tungsten ? config.warmup_tau_s / 10.0 : config.warmup_tau_s;
    const double dt = now - switched_on_at[i];
    if (!(dt < std::numeric_limits<double>::infinity())) return 1.0;
    return 1.0 - (1.0 - start) * std::exp(-std::max(dt, 0.0) / tau);
  }
  double output_locked(Lamp l, double now) const { return warmup_locked(l, now) * drift[index(l)].factor_at(now); }
};

double LampDrift::factor_at(double t) const {
  if (!(duration_s > 0) || rate_per_s == 0 || !(t > start_s)) return 1.0;
  double dt = t - start_s;
  if (returns && dt > duration_s) dt = std::max(0.0, 2.0 * duration_s - dt);
  return std::max(0.0, 1.0 + rate_per_s * std::min(dt, duration_s));
}

Scene::Scene(SceneConfig config, std::shared_ptr<const SimClock> clock) : impl_(std::make_unique<Impl>()) {
  if (!clock) throw Error(ErrorClass::bad_parameter, "Scene needs a SimClock");
  if (!(config.dimmer_percent_at_start >= 0.0 && config.dimmer_percent_at_start <= 100.0))
    throw Error(ErrorClass::bad_parameter, "SceneConfig.dimmer_percent_at_start must be within 0..100");
  if (!(config.warmup_tau_s > 0.0) || !(config.warmup_start_fraction > 0.0 && config.warmup_start_fraction <= 1.0))
    throw Error(ErrorClass::bad_parameter, "SceneConfig warm-up: tau must be > 0 and start fraction in (0, 1]");
  if (const auto& cab = config.geometric_cabinet) {
    verify::validate(*cab);
    if (cab->floor_reflectance != floor_reflectance())
      throw Error(ErrorClass::bad_parameter, "geometric cabinet: floor_reflectance must be the simulated floor's 0.3",
                  "the camera model and every instrument see a 0.30 grey floor; leave floor_reflectance out");
    if (cab->width_mm != cabinet_width_mm || cab->depth_mm != cabinet_depth_mm ||
        cab->grid_pitch_x_mm != floor_spot_pitch_x_mm || cab->grid_pitch_y_mm != floor_spot_pitch_y_mm)
      throw Error(ErrorClass::bad_parameter,
                  "geometric cabinet: the simulated floor is 1200 × 600 mm with its LS-110 grid at 60 × 54 mm",
                  "leave width_mm, depth_mm and grid_pitch_mm out (the height and the emitters may change)");
    for (const auto& e : cab->emitters)
      if (!(e.luminance_cd_m2 > 0.0))
        throw Error(ErrorClass::bad_parameter, "geometric cabinet: emitter " + e.lamp + " needs its luminance_cd_m2 (> 0)",
                    "the simulated lamp's brightness comes from it");
  }
  if (const auto& cab = config.geometric_cabinet) {
    config.chart_center_x_mm = cab->chart_center_x_mm;
    config.chart_center_y_mm = cab->chart_center_y_mm;
  }
  auto& m = *impl_;
  m.config = std::move(config);
  m.clock = std::move(clock);
  m.chart = detail::load_chart(m.config);
  const Spectrum y_bar = detail::load_y_bar();
  for (Lamp l : all_lamps) {
    const std::size_t i = index(l);
    m.lamp_spd[i] = detail::load_lamp_spectrum(l);
    m.lamp_on_grid[i] = m.lamp_spd[i].resampled(radiance_start_nm, radiance_step_nm, radiance_samples);
    m.lamp_y[i] = detail::photopic_integral(m.lamp_spd[i], y_bar);
    if (const auto& cab = m.config.geometric_cabinet)
      m.fields.emplace_back(verify::emitter_of(*cab, std::string(to_string(l))), cab->height_mm, cab->floor_reflectance);
    else
      m.fields.emplace_back(l, m.config.seed);
  }
  m.dimmer = m.config.dimmer_percent_at_start;
  for (Lamp l : m.config.lamps_on_at_start) {
    m.on[index(l)] = true;
    m.switched_on_at[index(l)] = -std::numeric_limits<double>::infinity();
  }
}

Scene::~Scene() = default;

void Scene::set_lamp(Lamp lamp, bool on) {
  const double now = impl_->clock->now();
  std::lock_guard lock(impl_->mutex);
  const std::size_t i = index(lamp);
  if (on && !impl_->on[i]) impl_->switched_on_at[i] = now;
  impl_->on[i] = on;
  ++impl_->version;
}

bool Scene::lamp_on(Lamp lamp) const {
  std::lock_guard lock(impl_->mutex);
  return impl_->on[index(lamp)];
}

std::vector<Lamp> Scene::lamps_on() const {
  std::lock_guard lock(impl_->mutex);
  std::vector<Lamp> out;
  for (Lamp l : all_lamps)
    if (impl_->on[index(l)]) out.push_back(l);
  return out;
}

void Scene::set_dimmer(double percent) {
  if (!(percent >= 0.0 && percent <= 100.0)) {
    throw Error(ErrorClass::bad_parameter, "dimmer setting " + std::to_string(percent) + " % is outside 0..100");
  }
  std::lock_guard lock(impl_->mutex);
  impl_->dimmer = percent;
  ++impl_->version;
}

double Scene::dimmer() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->dimmer;
}

double Scene::dimmer_output(double percent) { return detail::dimmer_output(percent); }

double Scene::warmup_factor(Lamp lamp) const {
  const double now = impl_->clock->now();
  std::lock_guard lock(impl_->mutex);
  return impl_->warmup_locked(lamp, now);
}

void Scene::set_lamp_drift(Lamp lamp, const LampDrift& drift) {
  if (!std::isfinite(drift.start_s) || !std::isfinite(drift.rate_per_s) || !std::isfinite(drift.duration_s) ||
      drift.duration_s < 0) {
    throw Error(ErrorClass::bad_parameter, "a lamp drift needs a finite start and rate and a duration >= 0");
  }
  std::lock_guard lock(impl_->mutex);
  impl_->drift[index(lamp)] = drift;
  ++impl_->version;
}

double Scene::drift_factor(Lamp lamp) const {
  const double now = impl_->clock->now();
  std::lock_guard lock(impl_->mutex);
  return impl_->drift[index(lamp)].factor_at(now);
}

double Scene::output_factor(Lamp lamp) const {
  const double now = impl_->clock->now();
  std::lock_guard lock(impl_->mutex);
  return impl_->output_locked(lamp, now);
}

std::uint64_t Scene::state_version() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->version;
}

std::pair<double, double> Scene::floor_spot_position_mm(int row, int col) {
  if (row < 0 || row >= floor_rows || col < 0 || col >= floor_cols) {
    throw Error(ErrorClass::bad_parameter, "floor spot (row " + std::to_string(row) + ", col " +
                                               std::to_string(col) + ") is off the 8 × 20 grid");
  }
  return {(col + 0.5) * floor_spot_pitch_x_mm, (row + 0.5) * floor_spot_pitch_y_mm};
}

double Scene::floor_luminance(int row, int col) const {
  const auto [x, y] = floor_spot_position_mm(row, col);
  return floor_luminance_at(x, y);
}

double Scene::floor_luminance_at(double x_mm, double y_mm) const {
  const double now = impl_->clock->now();
  std::lock_guard lock(impl_->mutex);
  double sum = 0.0;
  for (Lamp l : all_lamps) {
    if (!impl_->on[index(l)]) continue;
    sum += impl_->fields[index(l)].at(x_mm, y_mm, impl_->dimmer) * impl_->output_locked(l, now);
  }
  return sum;
}

double Scene::lamp_floor_luminance(Lamp lamp, double dimmer_percent, double x_mm, double y_mm) const {
  return impl_->fields[index(lamp)].at(x_mm, y_mm, dimmer_percent);
}

double Scene::luminance_noise_sigma(double cd_m2) const {
  // LS-110 repeatability: ±0.2 % + 1 digit (of the 4-digit display) at 2σ.
  const double digit = cd_m2 < 10 ? 0.001 : cd_m2 < 100 ? 0.01
                                        : cd_m2 < 1000  ? 0.1
                                                        : 1.0;
  return 0.5 * (0.002 * std::abs(cd_m2) + digit);
}

const Spectrum& Scene::lamp_spectrum(Lamp lamp) const { return impl_->lamp_spd[index(lamp)]; }

Spectrum Scene::spectral_radiance(double x_mm, double y_mm, const Spectrum& reflectance) const {
  const double now = impl_->clock->now();
  Spectrum out{radiance_start_nm, radiance_step_nm, std::vector<double>(radiance_samples, 0.0)};
  std::lock_guard lock(impl_->mutex);
  for (Lamp l : all_lamps) {
    const std::size_t i = index(l);
    if (!impl_->on[i]) continue;
    // Scale the relative SPD so that the grey floor (reflectance 0.30) has the field's luminance.
    const double floor_l = impl_->fields[i].at(x_mm, y_mm, impl_->dimmer) * impl_->output_locked(l, now);
    const double k = floor_l / (max_luminous_efficacy * floor_reflectance() * impl_->lamp_y[i]);
    const auto& s = impl_->lamp_on_grid[i].values;
    for (std::size_t j = 0; j < radiance_samples; ++j) out.values[j] += k * s[j];
  }
  for (std::size_t j = 0; j < radiance_samples; ++j) out.values[j] *= reflectance.at(out.wavelength(j));
  return out;
}

Spectrum Scene::lamp_radiance_per_cd(Lamp lamp, const Spectrum& reflectance) const {
  const std::size_t i = index(lamp);
  const double k = 1.0 / (max_luminous_efficacy * floor_reflectance() * impl_->lamp_y[i]);
  Spectrum out = impl_->lamp_on_grid[i];
  for (std::size_t j = 0; j < out.values.size(); ++j) out.values[j] *= k * reflectance.at(out.wavelength(j));
  return out;
}

namespace {
analysis::SpectralSet as_spectral_set(const Spectrum& s) {
  analysis::SpectralSet set;
  set.names = {"radiance"};
  set.source = "simulated scene";
  set.values.resize(1, static_cast<Eigen::Index>(s.values.size()));
  for (std::size_t i = 0; i < s.values.size(); ++i) {
    set.wavelengths.push_back(s.wavelength(i));
    set.values(0, static_cast<Eigen::Index>(i)) = s.values[i];
  }
  return set;
}
std::array<double, 3> radiance_xyz(const Spectrum& radiance) {
  const auto xyz = analysis::emission_to_xyz(as_spectral_set(radiance), analysis::Observer::cie1931_2deg, 683.0);
  return {xyz[0].X, xyz[0].Y, xyz[0].Z};
}
}  // namespace

std::array<double, 3> Scene::patch_xyz(int patch_index) const {
  const auto [x, y] = patch_floor_position_mm(patch_index);
  return radiance_xyz(spectral_radiance(x, y, impl_->chart.patches[static_cast<std::size_t>(patch_index)].reflectance));
}

std::array<double, 3> Scene::patch_lab(int patch_index) const {
  const auto [x, y] = patch_floor_position_mm(patch_index);
  const auto c = radiance_xyz(spectral_radiance(x, y, impl_->chart.patches[static_cast<std::size_t>(patch_index)].reflectance));
  const auto w = radiance_xyz(white_radiance(x, y));
  if (!(w[1] > 0.0)) {
    throw Error(ErrorClass::bad_parameter, "patch L*a*b* is undefined with every lamp off or the dimmer at 0");
  }
  const auto lab = analysis::xyz_to_lab({c[0], c[1], c[2]}, {w[0], w[1], w[2]});
  return {lab.L, lab.a, lab.b};
}

Spectrum Scene::white_radiance(double x_mm, double y_mm) const {
  const Spectrum white{radiance_start_nm, 350.0, {1.0, 1.0}};
  return spectral_radiance(x_mm, y_mm, white);
}

const Chart& Scene::chart() const { return impl_->chart; }

std::pair<double, double> Scene::chart_to_floor_mm(double chart_x_mm, double chart_y_mm) const {
  return {impl_->config.chart_center_x_mm - chart_width_mm / 2 + chart_x_mm,
          impl_->config.chart_center_y_mm + chart_height_mm / 2 - chart_y_mm};
}

std::pair<double, double> Scene::patch_floor_position_mm(int patch_index) const {
  if (patch_index < 0 || patch_index >= static_cast<int>(impl_->chart.patches.size())) {
    throw Error(ErrorClass::bad_parameter, "patch index " + std::to_string(patch_index) + " is outside 0..139");
  }
  const auto& p = impl_->chart.patches[static_cast<std::size_t>(patch_index)];
  return chart_to_floor_mm(p.x_mm + p.size_mm / 2, p.y_mm + p.size_mm / 2);
}

Scene::TableSample Scene::table_sample(double x_mm, double y_mm) const {
  if (!(x_mm >= 0 && x_mm <= table_width_mm && y_mm >= 0 && y_mm <= table_height_mm)) {
    throw Error(ErrorClass::bad_parameter, "table position (" + std::to_string(x_mm) + ", " + std::to_string(y_mm) +
                                               ") mm is outside the 310 × 230 mm SpectroScan T table");
  }
  const double cx = x_mm - impl_->config.chart_on_table_x_mm, cy = y_mm - impl_->config.chart_on_table_y_mm;
  if (cx < 0 || cy < 0 || cx >= chart_width_mm || cy >= chart_height_mm) return {std::nullopt, &impl_->table_plate};
  const auto patch = impl_->chart.patch_at(cx, cy);
  if (!patch) return {std::nullopt, &impl_->chart_surround};
  return {patch, &impl_->chart.patches[static_cast<std::size_t>(*patch)].reflectance};
}

const Spectrum& Scene::white_tile() const { return impl_->white_tile; }
const Spectrum& Scene::transmission_sample() const { return impl_->transmission; }

Spectrum Scene::noisy_reflectance(const Spectrum& truth, std::mt19937_64& rng) const {
  // Short-term repeatability of a Spectrolino: a common gain error (~0.1 %) plus per-band noise.
  std::normal_distribution<double> n01(0.0, 1.0);
  Spectrum out = truth;
  const double gain = 1.0 + 0.001 * n01(rng);
  for (double& v : out.values) v = v * gain + (0.0005 + 0.001 * std::abs(v)) * n01(rng);
  return out;
}

std::uint64_t Scene::seed() const { return impl_->config.seed; }

std::uint64_t Scene::stream_seed(std::string_view consumer) const {
  return splitmix64(impl_->config.seed ^ splitmix64(fnv1a(consumer)));
}

std::mt19937_64 Scene::rng_stream(std::string_view consumer) const { return std::mt19937_64(stream_seed(consumer)); }

const SimClock& Scene::clock() const { return *impl_->clock; }
const SceneConfig& Scene::config() const { return impl_->config; }

}  // namespace colorlab::sim
