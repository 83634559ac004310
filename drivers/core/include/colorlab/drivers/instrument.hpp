#pragma once
// The small, capability-based contract every instrument driver implements (after ArgyllCMS's
// inst.h and Bluesky's protocols): identity, a state machine, capabilities, calibration status,
// and asynchronous operations on the daemon's Asio executor. Simulated and real instruments are
// the same drivers on different ports; `simulated` only records which one it was.
#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include <boost/asio/awaitable.hpp>
#include <nlohmann/json_fwd.hpp>

namespace colorlab::drivers {

enum class InstrumentState {
  disconnected,
  initialising,
  ready,
  busy,
  needs_calibration,
  needs_operator,
  fault
};
std::string_view to_string(InstrumentState s);

// Down: only connect() brings it back (a run's first use and a suspension's recovery both ask this).
constexpr bool needs_connect(InstrumentState s) {
  return s == InstrumentState::disconnected || s == InstrumentState::fault;
}

enum class Capability {
  luminance,  // spot luminance in cd/m²
  reflectance_spectrum,
  emission_spectrum,
  transmission_spectrum,
  xy_table,
  lamp_switching,
  dimmer,
  camera,
};
std::string_view to_string(Capability c);

struct Identity {
  std::string kind;   // "ls110", "spectrolino", ...
  std::string model;  // as the instrument names itself
  std::string serial;
  std::string firmware;
  std::string port;  // where it is attached
  bool simulated = false;
};

struct CalibrationStatus {
  std::string type;  // "white", "emission", ...
  bool valid = false;
  std::optional<int> readings_left;  // count-based expiry
  std::optional<std::chrono::system_clock::time_point> valid_until;
};

class Instrument {
 public:
  virtual ~Instrument() = default;

  virtual const std::string& id() const = 0;
  virtual Identity identity() const = 0;
  virtual InstrumentState state() const = 0;
  virtual std::vector<Capability> capabilities() const = 0;
  virtual std::vector<CalibrationStatus> calibration() const { return {}; }
  // The last error's message and hint, for the API while state() is fault/needs_operator.
  virtual std::string last_problem() const { return {}; }

  // Opens the link and verifies the instrument's identity. Throws colorlab::Error.
  virtual boost::asio::awaitable<void> connect() = 0;
  virtual void disconnect() = 0;
};

struct LuminanceReading {
  double luminance = 0;  // in `unit`
  std::string unit = "cd/m2";
  std::chrono::system_clock::time_point time;
  std::string raw_reply;  // the instrument's own words, kept for provenance
};

class LuminanceMeter : public virtual Instrument {
 public:
  virtual boost::asio::awaitable<LuminanceReading> measure_luminance() = 0;
};

// The JSON the API and the run records use to describe an instrument.
nlohmann::json describe(const Instrument& instrument);

}  // namespace colorlab::drivers
