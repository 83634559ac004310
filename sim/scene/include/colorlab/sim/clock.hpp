#pragma once
// Simulated time. Every simulated instrument reads time from one SimClock so that a test can run an
// overnight campaign in minutes (time_scale 100 = a hundred simulated seconds per real second) while
// the durations the instruments report stay realistic.
#include <chrono>

namespace colorlab::sim {

class SimClock {
 public:
  // time_scale must be > 0; throws Error(bad_parameter) otherwise.
  explicit SimClock(double time_scale = 1.0);

  double time_scale() const noexcept { return scale_; }

  // Simulated seconds since construction (= real elapsed seconds × time_scale). Thread-safe.
  double now() const;

  // Real duration that corresponds to `sim_seconds` of simulated time (negative → zero).
  std::chrono::steady_clock::duration to_real(double sim_seconds) const;

  // Blocks the calling thread for `sim_seconds` of simulated time.
  void sleep_for(double sim_seconds) const;

 private:
  double scale_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace colorlab::sim
