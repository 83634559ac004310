#include "colorlab/sim/clock.hpp"

#include <cmath>
#include <string>
#include <thread>

#include "colorlab/core/error.hpp"

namespace colorlab::sim {

SimClock::SimClock(double time_scale) : scale_(time_scale), start_(std::chrono::steady_clock::now()) {
  if (!(time_scale > 0.0) || !std::isfinite(time_scale)) {
    throw Error(ErrorClass::bad_parameter, "SimClock: time_scale must be a positive number, got " +
                                               std::to_string(time_scale));
  }
}

double SimClock::now() const {
  const std::chrono::duration<double> real = std::chrono::steady_clock::now() - start_;
  return real.count() * scale_;
}

std::chrono::steady_clock::duration SimClock::to_real(double sim_seconds) const {
  if (!(sim_seconds > 0.0)) return std::chrono::steady_clock::duration::zero();
  return std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(sim_seconds / scale_));
}

void SimClock::sleep_for(double sim_seconds) const { std::this_thread::sleep_for(to_real(sim_seconds)); }

}  // namespace colorlab::sim
