#include "device_state.hpp"

namespace colorlab::sim::spectrolino_detail {

void DeviceSettings::power_on(int power_on_baud, sp::Filter filter) {
  baud = power_on_baud;
  handshake = sp::ctt::HandshakeNone;
  mode = sp::ctt::ModeReflectance;
  photometric = sp::ctt::PhotometricAbsolute;
  params = sp::ParameterAnswer{};
  params.filter = filter;
  button_enabled = true;
}

void ErrorState::power_on() {
  last = 0;
  new_measurement = sp::NewMeasurement::None;
}

void ErrorState::force(std::optional<std::uint8_t> code, bool once) {
  forced_ = code;
  forced_once_ = once;
}

std::optional<std::uint8_t> ErrorState::take_forced() {
  auto e = forced_;
  if (e && forced_once_) forced_.reset();
  return e;
}

}  // namespace colorlab::sim::spectrolino_detail
