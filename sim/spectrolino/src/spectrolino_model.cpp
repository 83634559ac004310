// SpectrolinoModel: construction, the power-on state and the public interface; each job is in its own file
// (see spectrolino_model_impl.hpp).
#include "colorlab/sim/spectrolino_model.hpp"

#include <string>

#include "colorlab/core/error.hpp"
#include "colorlab/sim/scene.hpp"
#include "spectrolino_model_impl.hpp"

namespace colorlab::sim {

namespace sp = wire::spectrolino;

SpectrolinoModel::Impl::Impl(const Scene& the_scene, SpectrolinoConfig the_config, std::uint64_t seed)
    : scene(the_scene), config(std::move(the_config)), rng(seed) {}

void SpectrolinoModel::Impl::power_cycle() {
  settings.power_on(config.power_on_baud, config.filter);
  errors.power_on();
  cal.power_on(spectrolino_detail::to_bands(scene.white_tile()));
  last.spectrum.reset();
  table.power_on(config.table);
}

SpectrolinoModel::SpectrolinoModel(const Scene& scene, SpectrolinoConfig config, std::uint64_t seed)
    : impl_(std::make_unique<Impl>(scene, std::move(config), seed)) {
  const int baud = impl_->config.power_on_baud;
  if (!sp::ctt_baud(sp::baud_ctt(baud).value_or(0))) {
    throw Error(ErrorClass::bad_parameter,
                "spectrolino power_on_baud " + std::to_string(baud) + " is not a Spectrolino speed",
                "use 110, 150, 300, 600, 1200, 2400, 4800, 9600, 19200, 28800 or 57600");
  }
  impl_->power_cycle();
}

SpectrolinoModel::~SpectrolinoModel() = default;

SpectrolinoReply SpectrolinoModel::handle(std::string_view line) { return impl_->handle(line); }

void SpectrolinoModel::power_cycle() { impl_->power_cycle(); }
void SpectrolinoModel::expire_calibration() { impl_->cal.expire(); }
void SpectrolinoModel::set_calibration_lifetime(double seconds) { impl_->cal.set_lifetime(seconds); }
void SpectrolinoModel::set_forced_exec_error(std::optional<std::uint8_t> code, bool once) {
  impl_->errors.force(code, once);
}

void SpectrolinoModel::place_head(double x_mm, double y_mm) {
  impl_->table.place(x_mm, y_mm);
  if (!impl_->config.table) impl_->table.head_down = true;
}

void SpectrolinoModel::place_on_tile() { place_head(impl_->config.tile_x_mm, impl_->config.tile_y_mm); }

void SpectrolinoModel::place_on_patch(int patch_index) {
  const auto& patches = impl_->scene.chart().patches;
  if (patch_index < 0 || patch_index >= static_cast<int>(patches.size())) {
    throw Error(ErrorClass::bad_parameter, "patch index " + std::to_string(patch_index) + " is not on the chart");
  }
  const auto& p = patches[static_cast<std::size_t>(patch_index)];
  const auto& c = impl_->config;
  place_head(c.chart_origin_x_mm + p.x_mm + p.size_mm / 2, c.chart_origin_y_mm + p.y_mm + p.size_mm / 2);
}

std::pair<double, double> SpectrolinoModel::head_mm() const { return impl_->table.head_mm(); }
bool SpectrolinoModel::head_on_tile() const { return impl_->table.on_tile(impl_->config); }
int SpectrolinoModel::baud() const { return impl_->settings.baud; }
bool SpectrolinoModel::calibrated() const { return impl_->calibration_valid(); }
const SpectrolinoConfig& SpectrolinoModel::config() const { return impl_->config; }
const SpectrolinoTiming& SpectrolinoModel::timing() const { return impl_->timing; }
sp::Spectrum SpectrolinoModel::true_reflectance() const { return impl_->target_spectrum(); }
sp::Spectrum SpectrolinoModel::surface_reflectance() const { return impl_->surface_reflectance(); }
std::optional<sp::Spectrum> SpectrolinoModel::last_spectrum() const { return impl_->last.spectrum; }
std::uint64_t SpectrolinoModel::measurements() const { return impl_->last.count; }

double SpectrolinoModel::move_seconds(double x_mm, double y_mm) const {
  return impl_->table.move_seconds(x_mm, y_mm, impl_->timing);
}

}  // namespace colorlab::sim
