#include "table_kinematics.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "colorlab/core/error.hpp"

namespace colorlab::sim::spectrolino_detail {

namespace sp = wire::spectrolino;

double axis_seconds(double d_mm, double v, double a) {
  d_mm = std::abs(d_mm);
  if (d_mm <= 0) return 0;
  if (d_mm < v * v / a) return 2.0 * std::sqrt(d_mm / a);
  return d_mm / v + v / a;
}

void ScanTable::power_on(bool table) {
  head_down = false;
  online = true;
  paper_held = false;
  digitizing = false;
  key_ack = false;
  special = 0;
  transmission = false;
  if (table) x = y = 0;
}

bool ScanTable::on_tile(const SpectrolinoConfig& config) const {
  auto [hx, hy] = head_mm();
  for (double ty : {config.tile_y_mm, config.tile_y_mm + kTile2OffsetYmm}) {
    if (std::hypot(hx - config.tile_x_mm, hy - ty) <= config.tile_radius_mm) return true;
  }
  return false;
}

void ScanTable::place(double x_mm, double y_mm) {
  if (x_mm < 0 || y_mm < 0 || x_mm > kTableMaxX / 10.0 || y_mm > kTableMaxY / 10.0) {
    throw Error(ErrorClass::bad_parameter, "head position (" + std::to_string(x_mm) + ", " + std::to_string(y_mm) +
                                               ") mm is off the 310 x 230 mm table");
  }
  x = static_cast<int>(std::lround(x_mm * 10));
  y = static_cast<int>(std::lround(y_mm * 10));
}

double ScanTable::move_seconds(double x_mm, double y_mm, const SpectrolinoTiming& t) const {
  auto [hx, hy] = head_mm();
  return std::max(axis_seconds(x_mm - hx, t.speed_mm_s, t.accel_mm_s2),
                  axis_seconds(y_mm - hy, t.speed_mm_s, t.accel_mm_s2));
}

TableResult ScanTable::move_to(int nx, int ny, const SpectrolinoTiming& t) {
  const double cmd = t.command_s;
  if (!online) return {sp::scan_err::DeviceIsOffline, cmd};
  if (transmission) return {sp::scan_err::NotInReflectMode, cmd};
  if (nx < 0 || ny < 0 || nx > kTableMaxX || ny > kTableMaxY) return {sp::scan_err::OutOfRange, cmd};
  double s = cmd;
  if (head_down && !(special & sp::status::SpecialHeadDownWhileMoving)) {
    s += t.head_s;
    head_down = false;
  }
  s += move_seconds(nx / 10.0, ny / 10.0, t);
  x = nx;
  y = ny;
  return {sp::scan_err::NoError, s};
}

TableResult ScanTable::set_head(bool down, const SpectrolinoTiming& t) {
  if (!online) return {sp::scan_err::DeviceIsOffline, t.command_s};
  double s = t.command_s + (head_down != down ? t.head_s : 0);
  head_down = down;
  return {sp::scan_err::NoError, s};
}

double ScanTable::initialize(const SpectrolinoTiming& t) {
  x = y = 0;
  head_down = false;
  online = true;
  paper_held = false;
  digitizing = false;
  return t.init_s;
}

double ScanTable::init_motor(const SpectrolinoTiming& t) {
  double s = move_seconds(0, 0, t) + t.head_s;
  x = y = 0;
  head_down = false;
  return s;
}

std::uint8_t ScanTable::set_light_level(std::uint8_t level) {
  if (!transmission) return sp::scan_err::NotInTransmMode;
  if (level > 2) return sp::scan_err::OutOfRange;
  light_level = level;
  return sp::scan_err::NoError;
}

std::uint8_t ScanTable::check_standby_position(int sx, int sy) const {
  if (!transmission) return sp::scan_err::NotInTransmMode;
  if (sx > kTableMaxX || sy > kTableMaxY) return sp::scan_err::OutOfRange;
  return sp::scan_err::NoError;
}

std::uint8_t ScanTable::status() const {
  std::uint8_t bits = 0;
  if (online) bits |= sp::status::Online;
  if (digitizing) bits |= sp::status::Digitizing;
  if (key_ack) bits |= sp::status::KeyAck;
  if (paper_held) bits |= sp::status::PaperHeld;
  return bits;
}

void ScanTable::clear_status(std::uint8_t bits) {
  if (bits & sp::status::Digitizing) digitizing = false;
  if (bits & sp::status::KeyAck) key_ack = false;
}

std::uint8_t ScanTable::special_status() const {
  std::uint8_t bits = special;
  if (transmission) bits |= sp::status::SpecialTransmission;
  return bits;
}

}  // namespace colorlab::sim::spectrolino_detail
