#include "calibration.hpp"

#include <algorithm>

#include "colorlab/sim/scene.hpp"
#include "spectrolino_model_impl.hpp"

namespace colorlab::sim {

namespace spectrolino_detail {

void WhiteCalibration::power_on(const sp::Spectrum& tile_certificate) {
  ratio_.reset();
  emission_ = false;
  set_white_reference(tile_certificate, 0);
}

void WhiteCalibration::expire() {
  ratio_.reset();
  emission_ = false;
}

bool WhiteCalibration::valid(std::uint8_t mode, double now) const {
  if (!ratio_) return false;
  if (mode != sp::ctt::ModeEmission && mode_ != mode) return false;
  if (lifetime_s_ > 0 && now - time_ > lifetime_s_) return false;
  return true;
}

void WhiteCalibration::calibrate_on_white(const sp::Spectrum& raw, std::uint8_t mode, double now) {
  sp::Spectrum ratio{};
  for (std::size_t i = 0; i < raw.size(); ++i) ratio[i] = white_reference_[i] / std::max(raw[i], 1e-6f);
  store(ratio, mode, now);
}

void WhiteCalibration::calibrate_open(std::uint8_t mode, double now) {
  sp::Spectrum ratio{};
  ratio.fill(1.0f);
  store(ratio, mode, now);
}

void WhiteCalibration::apply(sp::Spectrum& raw) const {
  for (std::size_t i = 0; i < raw.size(); ++i) raw[i] *= (*ratio_)[i];
}

void WhiteCalibration::set_white_reference(const sp::Spectrum& reference, std::uint8_t origin) {
  white_reference_ = reference;
  white_reference_origin_ = origin;
}

void WhiteCalibration::store(const sp::Spectrum& ratio, std::uint8_t mode, double now) {
  ratio_ = ratio;
  mode_ = mode;
  time_ = now;
}

}  // namespace spectrolino_detail

namespace sp = wire::spectrolino;

bool SpectrolinoModel::Impl::calibration_valid() const { return cal.valid(settings.mode, scene.clock().now()); }

std::uint8_t SpectrolinoModel::Impl::reference_measure(std::uint8_t mode, double& seconds) {
  seconds = timing.white_cal_s;
  if (mode == static_cast<std::uint8_t>(sp::RefMode::Normal)) return measure(seconds);
  if (auto e = errors.take_forced()) return *e;
  if (mode == static_cast<std::uint8_t>(sp::RefMode::EmissionCal)) {
    if (settings.mode != sp::ctt::ModeEmission) return sp::exec_err::OnlyEmission;
    cal.calibrate_emission();
    errors.new_measurement = sp::NewMeasurement::EmissionCal;
    return sp::exec_err::EmissionCalOK;
  }
  if (mode != static_cast<std::uint8_t>(sp::RefMode::WhiteCal) &&
      mode != static_cast<std::uint8_t>(sp::RefMode::WhiteCalWarn)) {
    return sp::exec_err::NoValidMeas;
  }
  if (settings.mode == sp::ctt::ModeTransmission) {
    cal.calibrate_open(settings.mode, scene.clock().now());
  } else {
    // The instrument cannot see what it is on; it only notices a white far from its tile certificate.
    if (!table.on_tile(config) || (config.table && !table.head_down)) return sp::exec_err::RemOverflow;
    sp::Spectrum raw = raw_under_head();
    cal.calibrate_on_white(raw, settings.mode, scene.clock().now());
  }
  errors.new_measurement = sp::NewMeasurement::WhiteCal;
  return sp::exec_err::WhiteMeasOK;
}

}  // namespace colorlab::sim
