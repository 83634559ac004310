#pragma once
// What a lab call costs, learned from the calls this lab has made. No source publishes how long a
// Spectrolino reading, a SpectroScan move or a lamp's warm-up takes (instrument-protocols.md gives
// only Argyll's timeouts), so the dry run's estimate comes from measured durations: the engine
// times every live call and stores it under a key that says what the time depends on (a cold lamp
// or a warm one, per frame and format for photographs, per operator action), and the dry run adds
// up the same keys. Keys never seen fall back to stated nominal figures, flagged as assumed.
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "colorlab/core/step_records.hpp"

namespace colorlab::campaigns {

// One live call's duration (colorlab/core/step_records.hpp says what it holds).
using CallTiming = records::CallTiming;

struct TimingStats {
  std::int64_t n = 0;
  double mean_s = 0;
};

// key → what it cost so far on this lab (at its time scale).
using TimingBook = std::map<std::string, TimingStats>;

// Follows a script's calls (live and replayed) and names the timing key of each; both the engine
// (to learn) and the dry run (to estimate) use it, so they cannot disagree on what a key means. What
// each call's key, units and waits are is its row's CallTimingRule (lab_calls.hpp).
class TimingKeys {
 public:
  // The key a call is timed under, known before the call is made.
  std::string key(const std::string& call, const nlohmann::json& args) const;
  // How many units the call counts for (frames × formats for a photograph), at least 1.
  static double units(const std::string& call, const nlohmann::json& args);
  // Lab seconds of the call that the script asked for outright (lab.wait, a dimmer's settle_s):
  // not learned, always added exactly.
  static double asked_wait_s(const std::string& call, const nlohmann::json& args);
  // Assumed lab seconds per unit for a key never timed on this lab: the row's nominal figure; a lamp
  // warm-up for a cold stability wait, one stability window for a warm one.
  static double nominal_s(const std::string& key, double lamp_warmup_s, double stability_window_s);
  // Whether the call under this key waits for a lamp to warm up (a stability wait with a cold lamp).
  static bool warms_up(const std::string& call, const std::string& key);
  // After a completed call: which lamps are lit, and which of them have been stable since.
  void follow(const std::string& call, const nlohmann::json& args, const nlohmann::json& result);
  // Lamps lit since the last stable wait (they still warm up): the next wait_stable waits for them.
  std::set<std::string> cold_lamps() const;

 private:
  std::set<std::string> lit_;
  std::set<std::string> warm_;
};

}  // namespace colorlab::campaigns
