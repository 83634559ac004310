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
//
// The implementation is split by job under sim/spectrolino/src/: command dispatch, the SpectroScan table's
// kinematics, white calibration, device settings and error state, measurement synthesis, colorimetry and
// densitometry.
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "colorlab/wire/spectrolino_protocol.hpp"

namespace colorlab::sim {

class Scene;

struct SpectrolinoConfig {
  bool table = true;  // false: a stand-alone Spectrolino (no D0 commands)
  int power_on_baud = 9600;
  std::uint32_t serial = 12345;  // Spectrolino serial (u16 in the 2B answer)
  std::uint32_t table_serial = 54321;
  wire::spectrolino::Filter filter = wire::spectrolino::Filter::None;  // the physical filter fitted
  double chart_origin_x_mm = 15.0;                                     // chart top-left corner on the table
  double chart_origin_y_mm = 7.0;
  double tile_x_mm = 298.0;  // white tile 1 (tile 2 is 30 mm further down)
  double tile_y_mm = 20.0;
  double tile_radius_mm = 6.0;  // head counts as "on the tile" within this distance
  double table_surface_reflectance = 0.80;
  double chart_border_reflectance = 0.035;  // the SG's black surround
  double emission_x_mm = 600.0;             // cabinet floor point read in emission mode
  double emission_y_mm = 140.0;
};

// What the answer is and what it does to the link.
struct SpectrolinoReply {
  std::string bytes;              // framed answer (":...\r\n"), empty when the device stays silent
  double device_seconds = 0;      // simulated instrument time before the answer starts
  std::optional<int> baud_after;  // the device listens at this speed once the answer is out
};

// Device timings (not published; plausible values, Argyll's timeouts bound them).
struct SpectrolinoTiming {
  double command_s = 0.02;
  double measure_s = 1.5;
  double white_cal_s = 1.5;
  double head_s = 0.3;        // head up or down
  double speed_mm_s = 250.0;  // table axes, trapezoidal profile
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
  void set_calibration_lifetime(double seconds);
  // An Error Type to answer measuring/calibrating commands with (e.g. 04 lamp failure) instead of measuring.
  void set_forced_exec_error(std::optional<std::uint8_t> code, bool once);

  // Stand-alone placement (and test aiming): put the head at a table position.
  void place_head(double x_mm, double y_mm);
  void place_on_tile();
  void place_on_patch(int patch_index);
  std::pair<double, double> head_mm() const;
  bool head_on_tile() const;

  int baud() const;
  bool calibrated() const;
  const SpectrolinoConfig& config() const;
  const SpectrolinoTiming& timing() const;
  // What the instrument would read now without noise (36 bands): the current mode's target, air when
  // the table's head is up. Ground truth.
  wire::spectrolino::Spectrum true_reflectance() const;
  // The true reflectance of the surface under the head (tile, patch, chart border or table), whatever
  // the mode or head state.
  wire::spectrolino::Spectrum surface_reflectance() const;
  // The last measured spectrum and its XYZ under the current parameters, for ground truth.
  std::optional<wire::spectrolino::Spectrum> last_spectrum() const;
  std::uint64_t measurements() const;

  // Seconds a move from the current position to (x, y) takes (both axes at once).
  double move_seconds(double x_mm, double y_mm) const;

 private:
  // The model's state, one part per job (sim/spectrolino/src/spectrolino_model_impl.hpp).
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace colorlab::sim
