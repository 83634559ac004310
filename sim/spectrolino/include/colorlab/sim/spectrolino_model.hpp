#pragma once
// The Spectrolino on a SpectroScan T as a pure request → answer state machine (no I/O), so golden
// transcripts and determinism can be tested byte for byte without a pty. SpectrolinoSim puts it on a
// pty and adds pacing, speed checks and faults.
//
// Physics: the measuring head sits at a table position (0..310 × 0..230 mm, 0.1 mm steps). The
// ColorChecker SG from the Scene lies on the table with its top-left corner at chart_origin; the white
// tile is at a fixed position. Reflectance readings are the true reflectance under the head with the
// Scene's Spectrolino noise, scaled by the white calibration (tile certificate / what was under the head
// at calibration). Emission reads the cabinet's irradiance; transmission reads the Scene's filter sample.
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <string_view>

#include "colorlab/wire/spectrolino_protocol.hpp"

namespace colorlab::sim {

class Scene;

struct SpectrolinoConfig {
  bool table = true;                 // false: a stand-alone Spectrolino (no D0 commands)
  int power_on_baud = 9600;
  std::uint32_t serial = 12345;      // Spectrolino serial (u16 in the 2B answer)
  std::uint32_t table_serial = 54321;
  wire::spectrolino::Filter filter = wire::spectrolino::Filter::None;  // the physical filter fitted
  double chart_origin_x_mm = 15.0;   // chart top-left corner on the table
  double chart_origin_y_mm = 7.0;
  double tile_x_mm = 298.0;          // white tile 1 (tile 2 is 30 mm further down)
  double tile_y_mm = 20.0;
  double tile_radius_mm = 6.0;       // head counts as "on the tile" within this distance
  double table_surface_reflectance = 0.80;
  double chart_border_reflectance = 0.035;  // the SG's black surround
  double emission_x_mm = 600.0;      // cabinet floor point read in emission mode
  double emission_y_mm = 140.0;
};

// What the answer is and what it does to the link.
struct SpectrolinoReply {
  std::string bytes;                 // framed answer (":...\r\n"), empty when the device stays silent
  double device_seconds = 0;         // simulated instrument time before the answer starts
  std::optional<int> baud_after;     // the device listens at this speed once the answer is out
};

// Device timings (not published; plausible values, Argyll's timeouts bound them).
struct SpectrolinoTiming {
  double command_s = 0.02;
  double measure_s = 1.5;
  double white_cal_s = 1.5;
  double head_s = 0.3;            // head up or down
  double speed_mm_s = 250.0;      // table axes, trapezoidal profile
  double accel_mm_s2 = 1000.0;
  double init_s = 3.0;
  double reset_s = 1.0;
};

class SpectrolinoModel {
 public:
  SpectrolinoModel(const Scene& scene, SpectrolinoConfig config, std::uint64_t seed);
  ~SpectrolinoModel();

  // One complete request line (";...\r\n" or without CR LF). Lines not starting with ';' get COM error 01.
  SpectrolinoReply handle(std::string_view line);

  // Back to the power-on state (speed, no calibration, table home and online).
  void power_cycle();
  // Forget the white calibration (calibration expiry).
  void expire_calibration();
  // Calibrations older than this (simulated seconds) no longer count; 0 = never expire.
  void set_calibration_lifetime(double seconds) { cal_lifetime_s_ = seconds; }
  // An Error Type to answer measuring/calibrating commands with (e.g. 04 lamp failure) instead of measuring.
  void set_forced_exec_error(std::optional<std::uint8_t> code, bool once);

  // Stand-alone placement (and test aiming): put the head at a table position.
  void place_head(double x_mm, double y_mm);
  void place_on_tile() { place_head(config_.tile_x_mm, config_.tile_y_mm); }
  void place_on_patch(int patch_index);
  std::pair<double, double> head_mm() const;
  bool head_on_tile() const;

  int baud() const { return baud_; }
  bool calibrated() const;
  const SpectrolinoConfig& config() const { return config_; }
  const SpectrolinoTiming& timing() const { return timing_; }
  // What the instrument would read now without noise (36 bands): the current mode's target, air when
  // the table's head is up. Ground truth.
  wire::spectrolino::Spectrum true_reflectance() const;
  // The true reflectance of the surface under the head (tile, patch, chart border or table), whatever
  // the mode or head state.
  wire::spectrolino::Spectrum surface_reflectance() const;
  // The last measured spectrum and its XYZ under the current parameters, for ground truth.
  std::optional<wire::spectrolino::Spectrum> last_spectrum() const;
  std::uint64_t measurements() const { return measurements_; }

  // Seconds a move from the current position to (x, y) takes (both axes at once).
  double move_seconds(double x_mm, double y_mm) const;

 private:
  using Bytes = wire::spectrolino::Bytes;
  SpectrolinoReply spectrolino(const wire::spectrolino::Request& r, std::size_t request_bytes);
  SpectrolinoReply spectroscan(const wire::spectrolino::Request& r);
  SpectrolinoReply answer(const Bytes& body, double seconds) const;
  SpectrolinoReply com_error(std::uint8_t code) const;
  SpectrolinoReply scan_error(std::uint8_t code, double seconds) const;

  std::uint8_t measure(double& seconds);          // ExecMeasurement: returns the error type
  std::uint8_t reference_measure(std::uint8_t mode, double& seconds);
  wire::spectrolino::Spectrum raw_under_head();   // what the optics see now, before calibration
  wire::spectrolino::Spectrum target_spectrum() const;  // truth for the current mode and place
  std::optional<std::uint8_t> take_forced_error();
  bool calibration_valid() const;
  // XYZ/xyY/Lab of the last spectrum; nullopt when the colour type or illuminant is unsupported.
  std::optional<std::array<float, 3>> colour(wire::spectrolino::ColourType type, std::uint16_t& rem);

  const Scene& scene_;
  SpectrolinoConfig config_;
  SpectrolinoTiming timing_;
  std::mt19937_64 rng_;

  // Spectrolino state
  int baud_ = 9600;
  std::uint8_t handshake_ = wire::spectrolino::ctt::HandshakeNone;
  std::uint8_t mode_ = wire::spectrolino::ctt::ModeReflectance;
  std::uint8_t photometric_ = wire::spectrolino::ctt::PhotometricAbsolute;
  std::uint8_t speaker_ = wire::spectrolino::ctt::SpeakerOn;
  wire::spectrolino::ParameterAnswer params_;
  std::optional<wire::spectrolino::Spectrum> cal_ratio_;  // per band, from the last white calibration
  double cal_time_ = 0;
  std::uint8_t cal_mode_ = wire::spectrolino::ctt::ModeReflectance;  // a calibration serves one mode
  bool emission_cal_ = false;
  double cal_lifetime_s_ = 0;
  bool button_enabled_ = true;
  wire::spectrolino::NewMeasurement new_meas_ = wire::spectrolino::NewMeasurement::None;
  std::optional<wire::spectrolino::Spectrum> last_;
  std::uint8_t last_mode_ = wire::spectrolino::ctt::ModeReflectance;
  std::uint8_t last_error_ = 0;
  std::optional<std::uint8_t> forced_error_;
  bool forced_once_ = false;
  std::optional<wire::spectrolino::Spectrum> user_illuminant_;
  std::uint8_t dxx_ = 50;
  float photometric_ref_ = 1.0f;
  std::array<float, 4> slope_{1, 1, 1, 1};
  wire::spectrolino::Spectrum white_reference_{};
  std::uint8_t white_reference_origin_ = 0;
  std::uint64_t measurements_ = 0;

  // SpectroScan state (0.1 mm units)
  int x_ = 0, y_ = 0;
  bool head_down_ = false;
  bool online_ = true;
  bool paper_held_ = false;
  bool digitizing_ = false;
  bool key_ack_ = false;
  std::uint8_t status_clear_mask_ = 0;
  std::uint8_t special_ = 0;
  bool transmission_table_ = false;
  std::uint8_t light_level_ = 0;

  struct Integrators;
  std::unique_ptr<Integrators> integrators_;
};

}  // namespace colorlab::sim
