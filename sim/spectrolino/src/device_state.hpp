#pragma once
// Device settings and error state of the simulated Spectrolino: what the host sets and reads back (speed,
// handshake, measuring mode, parameters, user illuminant, slopes, ...), the Error Type of the last execution,
// an injected Error Type, and the new-measurement flag. Private to sim/spectrolino.
#include <array>
#include <cstdint>
#include <optional>

#include "colorlab/wire/spectrolino_protocol.hpp"

namespace colorlab::sim::spectrolino_detail {

namespace sp = wire::spectrolino;

// What the host sets with 4D, 16, 17, 33, 3A and C2 (and reads with 5B, 00, 01, 38, 47 and C0).
struct DeviceSettings {
  int baud = 9600;
  std::uint8_t handshake = sp::ctt::HandshakeNone;
  std::uint8_t mode = sp::ctt::ModeReflectance;
  std::uint8_t photometric = sp::ctt::PhotometricAbsolute;
  std::uint8_t speaker = sp::ctt::SpeakerOn;
  sp::ParameterAnswer params;
  bool button_enabled = true;
  std::optional<sp::Spectrum> user_illuminant;
  std::uint8_t dxx = 50;  // Dxx illuminant, in hundreds of kelvin
  float photometric_ref = 1.0f;
  std::array<float, 4> slope{1, 1, 1, 1};

  // Power-on values; the speaker, user illuminant, Dxx, photometric reference and slopes are kept.
  void power_on(int power_on_baud, sp::Filter filter);
};

// The Error Type the device reports (29 ActErrorRequest), a fault-injected one, and the 07 flag.
class ErrorState {
 public:
  std::uint8_t last = 0;  // of the last measuring or calibrating command
  sp::NewMeasurement new_measurement = sp::NewMeasurement::None;

  // Power-on: no error, nothing new; an injected error stays until the fault is changed.
  void power_on();
  void force(std::optional<std::uint8_t> code, bool once);
  // The injected Error Type to answer instead of executing, if any (consumed when `once`).
  std::optional<std::uint8_t> take_forced();

 private:
  std::optional<std::uint8_t> forced_;
  bool forced_once_ = false;
};

}  // namespace colorlab::sim::spectrolino_detail
