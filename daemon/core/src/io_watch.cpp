#include "colorlab/daemon/io_watch.hpp"

#include <cstdio>
#include <cstdlib>

#include <boost/asio/steady_timer.hpp>

#include "colorlab/core/log.hpp"
#include "colorlab/core/thread_account.hpp"

namespace colorlab::daemon {

namespace {

using Clock = std::chrono::steady_clock;

long env_ms(const char* name, long fallback) {
  const char* text = std::getenv(name);
  if (!text || !*text) return fallback;
  char* end = nullptr;
  long v = std::strtol(text, &end, 10);
  return end && *end == '\0' && v > 0 ? v : fallback;
}

std::string ms_text(std::chrono::microseconds us) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", static_cast<double>(us.count()) / 1000.0);
  return buf;
}

}  // namespace

std::chrono::microseconds io_slow_threshold() {
  static const std::chrono::microseconds threshold = std::chrono::milliseconds(env_ms("COLORLAB_IO_SLOW_MS", 50));
  return threshold;
}

IoStage::IoStage(std::string_view stage) : stage_(stage), start_(Clock::now()), cpu_start_(this_thread_cpu_time()) {}

IoStage::~IoStage() {
  const auto took = std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - start_);
  if (took <= io_slow_threshold()) return;
  const auto cpu = std::chrono::duration_cast<std::chrono::microseconds>(this_thread_cpu_time() - cpu_start_);
  log::warning("io-thread", "slow stage '" + std::string(stage_) + "' took " + ms_text(took) + " ms, on a CPU " +
                                ms_text(cpu) + " ms (limit " + ms_text(io_slow_threshold()) + " ms)");
}

struct IoLagMonitor::State {
  explicit State(boost::asio::any_io_executor io) : timer(io) {}
  boost::asio::steady_timer timer;
  std::chrono::milliseconds tick{0};
  Clock::time_point armed, due;
  ThreadAccount at_arming;  // the io thread's own account when the tick was armed
  bool stopped = false;

  static void schedule(const std::shared_ptr<State>& self) {
    self->armed = Clock::now();
    self->at_arming = this_thread_account();
    self->due = self->armed + self->tick;
    self->timer.expires_at(self->due);
    self->timer.async_wait([weak = std::weak_ptr<State>(self)](boost::system::error_code ec) {
      auto s = weak.lock();
      if (ec || !s || s->stopped) return;
      const auto now = Clock::now();
      const auto late = std::chrono::duration_cast<std::chrono::microseconds>(now - s->due);
      if (late > io_slow_threshold()) {
        // Over the whole interval (tick + lateness): working, waiting for a CPU, or blocked.
        const std::string split = split_of_interval(now - s->armed, s->at_arming, this_thread_account());
        log::warning("io-thread", "the io thread was busy: a " + std::to_string(s->tick.count()) + " ms tick fired " +
                                      ms_text(late) + " ms late" + (split.empty() ? "" : " (" + split + ")"));
      }
      schedule(s);
    });
  }
};

IoLagMonitor::IoLagMonitor(boost::asio::any_io_executor io) : state_(std::make_shared<State>(std::move(io))) {
  state_->tick = std::chrono::milliseconds(env_ms("COLORLAB_IO_LAG_MS", 0));
}

IoLagMonitor::~IoLagMonitor() { stop(); }

void IoLagMonitor::start() {
  if (state_->tick.count() <= 0) return;
  log::info("io-thread", "watching the io thread's lag every " + std::to_string(state_->tick.count()) + " ms");
  State::schedule(state_);
}

void IoLagMonitor::stop() {
  state_->stopped = true;
  state_->timer.cancel();
}

}  // namespace colorlab::daemon
