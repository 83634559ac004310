#pragma once
// Which work holds colorlabd's io (main) thread, and for how long (issue 27: every `main` route must answer
// within 50 ms through any campaign, and nothing on that thread may take longer than that).
//
// IoStage times one stage of work on the io thread (a route's handler, a step's commit, an event-stream
// snapshot, a script's slice) and logs one line naming it when it took longer than the threshold:
//   io-thread: slow stage 'route GET /v1/control' took 73.1 ms, on a CPU 1.2 ms (limit 50 ms)
// IoLagMonitor (opt-in: COLORLAB_IO_LAG_MS, a tick in ms) schedules a timer on the io thread and logs how
// late it fired when it was later than the threshold: that is the io thread busy with something, stage or
// not, so the stages' lines and its lines together attribute every stall (docs/PERFORMANCE.md).
// The threshold is COLORLAB_IO_SLOW_MS (default 50, the target). Both are diagnostics: they change
// nothing the daemon does.
#include <chrono>
#include <memory>
#include <string>
#include <string_view>

#include <boost/asio/any_io_executor.hpp>

namespace colorlab::daemon {

std::chrono::microseconds io_slow_threshold();

class IoStage {
 public:
  explicit IoStage(std::string_view stage);
  ~IoStage();
  IoStage(const IoStage&) = delete;
  IoStage& operator=(const IoStage&) = delete;

 private:
  std::string_view stage_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::nanoseconds cpu_start_;  // a slow stage's line says how much of it was work
};

// The same, for a stage whose name is made at run time (a route's method and pattern).
class NamedIoStage {
 public:
  explicit NamedIoStage(std::string stage) : stage_(std::move(stage)), timer_(stage_) {}

 private:
  std::string stage_;
  IoStage timer_;
};

class IoLagMonitor {
 public:
  // Does nothing unless COLORLAB_IO_LAG_MS is set (a positive number of ms between ticks).
  explicit IoLagMonitor(boost::asio::any_io_executor io);
  ~IoLagMonitor();
  IoLagMonitor(const IoLagMonitor&) = delete;
  IoLagMonitor& operator=(const IoLagMonitor&) = delete;
  void start();
  void stop();

 private:
  struct State;
  std::shared_ptr<State> state_;
};

}  // namespace colorlab::daemon
