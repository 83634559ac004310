#pragma once
// Capability interfaces beyond luminance: spectrometers, XY tables, lamp switching and dimming.
// Campaigns depend on these, never on a concrete driver, so a relay board and a DMX dimmer (or a
// stand-alone Spectrolino and one on a SpectroScan T) are interchangeable where they can be.
#include <array>
#include <chrono>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <boost/asio/awaitable.hpp>

#include "colorlab/drivers/instrument.hpp"

namespace colorlab::drivers {

enum class SpectralMode {
  reflectance,
  emission,
  transmission
};
std::string_view to_string(SpectralMode m);

struct SpectralReading {
  SpectralMode mode = SpectralMode::reflectance;
  double first_nm = 380;
  double step_nm = 10;
  // Reflectance/transmittance as fractions (0–1); emission in mW/(nm·m²) as the instrument reports it.
  std::vector<double> values;
  // Computed by colorlab from `values` (not queried from the instrument); Y of the perfect reflector = 100.
  std::optional<std::array<double, 3>> xyz;
  std::chrono::system_clock::time_point time;
  int attempts = 1;  // how many tries the reading needed
};

class Spectrometer : public virtual Instrument {
 public:
  virtual boost::asio::awaitable<void> set_mode(SpectralMode mode) = 0;
  // Brings the instrument onto its white reference (or asks an operator to) and calibrates.
  virtual boost::asio::awaitable<void> calibrate() = 0;
  virtual boost::asio::awaitable<SpectralReading> measure() = 0;
};

struct TablePosition {
  double x_mm = 0;
  double y_mm = 0;
  bool head_down = false;
};

// One patch of a chart read in the table's visiting order. `row_start` and `row_length` let the
// table decide at a row's first patch whether its white calibration would run out within the row.
struct ChartPatchVisit {
  int index = 0;  // the patch's number in the chart's own order (for messages)
  double x_mm = 0, y_mm = 0;
  bool row_start = false;
  int row_length = 1;
};

// The area the measuring head can reach, from the table's origin.
struct TableTravel {
  double x_max_mm = 0;
  double y_max_mm = 0;
};

class XyTable : public virtual Instrument {
 public:
  // Where the head can go (a dry run checks a campaign's positions against it); nullopt if unknown.
  virtual std::optional<TableTravel> travel() const { return std::nullopt; }
  virtual boost::asio::awaitable<void> move_to(double x_mm, double y_mm) = 0;
  virtual boost::asio::awaitable<void> home() = 0;
  virtual boost::asio::awaitable<void> head_up() = 0;
  virtual boost::asio::awaitable<void> head_down() = 0;
  virtual boost::asio::awaitable<void> hold_paper(bool hold) = 0;
  virtual boost::asio::awaitable<TablePosition> position() = 0;
  // Move, lower, measure, raise in one table command.
  virtual boost::asio::awaitable<SpectralReading> move_and_measure(double x_mm, double y_mm) = 0;
  // move_and_measure with the table's chart-reading policy: calibration when due (and before a
  // row it would not last through), retries with recalibration, reconnection after a lost link.
  virtual boost::asio::awaitable<SpectralReading> read_chart_patch(const ChartPatchVisit& visit) = 0;
};

class LampController : public virtual Instrument {
 public:
  virtual std::vector<std::string> lamp_names() const = 0;
  // Exactly `on` lit, every other lamp off; refuses more than one lamp unless configured to allow it.
  virtual boost::asio::awaitable<void> set_lamps(std::vector<std::string> on) = 0;
  virtual std::vector<std::string> lamps_on() const = 0;
};

class Dimmer : public virtual Instrument {
 public:
  // level 0–1; returns once the ramp and the settle time are over.
  virtual boost::asio::awaitable<void> set_level(const std::string& lamp, double level) = 0;
  virtual double level(const std::string& lamp) const = 0;
  // The levels the dimmer can hold (0–1); a ballast may not dim below some level.
  virtual std::pair<double, double> level_range() const { return {0.0, 1.0}; }
};

}  // namespace colorlab::drivers
