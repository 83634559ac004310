#pragma once
// The live side of the lab API: carries out a script's calls on the daemon's instruments, by role
// (the first instrument offering the capability), waiting for an instrument that is still
// connecting. Also brings the lab back to a journal's desired state after a resume, and to a safe
// state at shutdown. Times a script gives are lab seconds; with the simulated lab they shrink by
// its time scale.
#include <chrono>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/awaitable.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/campaigns/control.hpp"
#include "colorlab/campaigns/instrument_set.hpp"
#include "colorlab/campaigns/lab_state.hpp"

namespace colorlab::campaigns {

struct StabilityCriterion {
  double tolerance_pct = 0.5;  // drift over the window, from a straight-line fit, in % of the mean
  double window_s = 60;        // lab seconds
  double interval_s = 5;       // lab seconds between readings
  double timeout_s = 1800;     // lab seconds
  static StabilityCriterion from_json(const nlohmann::json& j, const StabilityCriterion& defaults);
};

struct LabOptions {
  double time_scale = 1;              // lab seconds per wall-clock second (the simulator's time scale)
  StabilityCriterion warmup;          // how a resume decides that relit lamps are stable again
  double lamp_warmup_s = 900;         // with no luminance meter: wait this long after relighting
  bool lamps_off_at_shutdown = false; // otherwise lamps stay as they are (a warm cabinet for the next run)
  std::chrono::seconds connect_timeout{60};
};

class Lab {
 public:
  Lab(boost::asio::any_io_executor executor, const InstrumentSet& instruments, LabOptions options);

  // Throws Error{not_found} naming the first role no configured instrument offers.
  void check_needs(const std::vector<std::string>& roles) const;
  // One lab call, live. Long waits end early with Error{aborted} when `control` asks.
  boost::asio::awaitable<nlohmann::json> perform(const std::string& call, const nlohmann::json& args,
                                                 const ExecutionControl& control);
  // Brings the instruments to `desired`; returns what it did, for the event log.
  boost::asio::awaitable<nlohmann::json> restore(const LabState& desired, const ExecutionControl& control);
  // Table home with the head up; lamps off if configured. Errors are logged, not thrown.
  boost::asio::awaitable<void> safe_state();
  // Connects the instruments named in `expected` (id → serial the run started with) and lists those
  // that now report another serial: "id: the run started with serial A, now B".
  boost::asio::awaitable<std::vector<std::string>> serial_mismatches(std::map<std::string, std::string> expected);

  const LabOptions& options() const { return options_; }
  double time_scale() const { return options_.time_scale; }

 private:
  template <class T>
  std::shared_ptr<T> role(const std::string& name) const;  // or Error{not_found}
  template <class T>
  std::shared_ptr<T> find_role(const std::string& name) const;  // or nullptr
  // The role's instrument, connected (connecting candidates first if none offers it yet).
  template <class T>
  boost::asio::awaitable<std::shared_ptr<T>> acquire(const std::string& name);
  template <class T>
  bool may_offer(const std::string& name) const;
  boost::asio::awaitable<void> ready(drivers::Instrument& instrument);
  boost::asio::awaitable<void> sleep_lab_seconds(double seconds, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> wait_stable(const StabilityCriterion& c, const ExecutionControl& control);
  boost::asio::awaitable<void> switch_lamps(std::vector<std::string> on);

  boost::asio::any_io_executor executor_;
  const InstrumentSet& instruments_;
  LabOptions options_;
  // Lamps this process has seen lit and stable since it last switched them: a resume in the same
  // process need not wait for them again; a fresh process knows nothing and waits.
  std::set<std::string> known_warm_;
};

}  // namespace colorlab::campaigns
