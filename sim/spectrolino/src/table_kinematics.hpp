#pragma once
// SpectroScan T table kinematics: the head's position in 0.1 mm steps on the 310 x 230 mm table, moves on a
// trapezoidal speed profile (both axes at once) that raise the head first, head up/down, and the table's
// switches (online, paper hold, digitizing, key acknowledge, special status, reflection/transmission table,
// light level) with the status bytes they make. Private to sim/spectrolino.
#include <cstdint>
#include <utility>

#include "colorlab/sim/spectrolino_model.hpp"

namespace colorlab::sim::spectrolino_detail {

inline constexpr int kTableMaxX = 3100;  // 0.1 mm
inline constexpr int kTableMaxY = 2300;
inline constexpr double kTile2OffsetYmm = 30.0;  // white tile 2 below tile 1

// Seconds one axis takes for d_mm at top speed v and acceleration a (triangular when it never reaches v).
double axis_seconds(double d_mm, double v, double a);

// What a table command did: its Scan Error and the device time it took.
struct TableResult {
  std::uint8_t scan_error = 0;
  double seconds = 0;
};

struct ScanTable {
  int x = 0, y = 0;  // 0.1 mm
  bool head_down = false;
  bool online = true;
  bool paper_held = false;
  bool digitizing = false;
  bool key_ack = false;
  std::uint8_t special = 0;
  bool transmission = false;  // the light table is in transmission mode
  std::uint8_t light_level = 0;

  // Power-on: head up, online, paper released, not digitizing, special status and table mode cleared. The
  // position goes home only on a table (a stand-alone Spectrolino stays where it was put).
  void power_on(bool table);

  std::pair<double, double> head_mm() const { return {x / 10.0, y / 10.0}; }
  // Within tile_radius_mm of white tile 1 or 2.
  bool on_tile(const SpectrolinoConfig& config) const;
  // Puts the head at a table position; throws Error{bad_parameter} off the table.
  void place(double x_mm, double y_mm);
  double move_seconds(double x_mm, double y_mm, const SpectrolinoTiming& t) const;

  // D0 00/01/02/06: refused offline, in transmission mode and off the table; raises the head first unless
  // "keep head down while moving" is set.
  TableResult move_to(int nx, int ny, const SpectrolinoTiming& t);
  // D0 03/04: refused offline.
  TableResult set_head(bool down, const SpectrolinoTiming& t);
  // D0 0A: home, head up, online, paper released, not digitizing.
  double initialize(const SpectrolinoTiming& t);
  // D0 0C: drive home and raise the head.
  double init_motor(const SpectrolinoTiming& t);
  // D0 0E: levels 0..2, in transmission mode only.
  std::uint8_t set_light_level(std::uint8_t level);
  // D0 0F: the standby position must be on the table, in transmission mode only.
  std::uint8_t check_standby_position(int sx, int sy) const;

  std::uint8_t status() const;           // D0 24
  void clear_status(std::uint8_t bits);  // D0 25
  std::uint8_t special_status() const;   // D0 28
};

}  // namespace colorlab::sim::spectrolino_detail
