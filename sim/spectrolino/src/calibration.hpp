#pragma once
// White calibration of the simulated Spectrolino: the white reference (the tile's certificate, or one the host
// downloaded), the per-band ratio the last white calibration found, the mode it serves, its age against an
// optional lifetime, and the emission calibration. Private to sim/spectrolino.
#include <cstdint>
#include <optional>

#include "colorlab/wire/spectrolino_protocol.hpp"

namespace colorlab::sim::spectrolino_detail {

namespace sp = wire::spectrolino;

class WhiteCalibration {
 public:
  // Power-on: no calibration, the tile certificate as white reference.
  void power_on(const sp::Spectrum& tile_certificate);
  // Calibration expiry: forget the white and the emission calibration.
  void expire();
  void set_lifetime(double seconds) { lifetime_s_ = seconds; }

  // A white calibration counts in `mode` at time `now`: one was made, for that mode (any serves emission), and
  // it is not older than the lifetime.
  bool valid(std::uint8_t mode, double now) const;
  bool emission_calibrated() const { return emission_; }

  // Calibrate on white: the ratio per band of the white reference to what the optics saw.
  void calibrate_on_white(const sp::Spectrum& raw, std::uint8_t mode, double now);
  // Transmission: the open light table is the 100 % reference.
  void calibrate_open(std::uint8_t mode, double now);
  void calibrate_emission() { emission_ = true; }
  // Scale a raw reading by the calibration (valid() must hold).
  void apply(sp::Spectrum& raw) const;

  // The white reference (B3 / B7 / 4A) and where it came from (0 the tile's certificate, 1 downloaded).
  const sp::Spectrum& white_reference() const { return white_reference_; }
  std::uint8_t white_reference_origin() const { return white_reference_origin_; }
  void set_white_reference(const sp::Spectrum& reference, std::uint8_t origin);

 private:
  void store(const sp::Spectrum& ratio, std::uint8_t mode, double now);

  std::optional<sp::Spectrum> ratio_;
  double time_ = 0;
  std::uint8_t mode_ = sp::ctt::ModeReflectance;  // a calibration serves one mode
  bool emission_ = false;
  double lifetime_s_ = 0;
  sp::Spectrum white_reference_{};
  std::uint8_t white_reference_origin_ = 0;
};

}  // namespace colorlab::sim::spectrolino_detail
