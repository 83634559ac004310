#include "colorlab/drivers/reconnect.hpp"

#include <algorithm>
#include <optional>

#include <boost/asio/steady_timer.hpp>
#include <boost/asio/use_awaitable.hpp>

#include "colorlab/core/log.hpp"

namespace colorlab::drivers {

namespace asio = boost::asio;

std::chrono::milliseconds ReconnectPolicy::backoff(int attempt) const {
  double ms = static_cast<double>(initial_backoff.count());
  for (int i = 1; i < attempt; ++i) ms *= backoff_factor;
  return std::min(max_backoff, std::chrono::milliseconds(static_cast<long long>(ms)));
}

std::string_view to_string(ReconnectPhase p) {
  switch (p) {
    case ReconnectPhase::idle: return "idle";
    case ReconnectPhase::closing: return "closing";
    case ReconnectPhase::backing_off: return "backing_off";
    case ReconnectPhase::reopening: return "reopening";
    case ReconnectPhase::verifying: return "verifying";
    case ReconnectPhase::connected: return "connected";
    case ReconnectPhase::gave_up: return "gave_up";
  }
  return "idle";
}

bool calls_for_reconnect(const Error& e) {
  return e.cls() == ErrorClass::no_comms || e.cls() == ErrorClass::timeout || e.cls() == ErrorClass::coms_fail;
}

Reconnector::Reconnector(asio::any_io_executor executor, ReconnectPolicy policy)
    : executor_(executor), policy_(policy) {}

asio::awaitable<void> Reconnector::reconnect(Instrument& instrument) {
  const Verify none;
  co_await reconnect(instrument, none);
}

asio::awaitable<void> Reconnector::reconnect(Instrument& instrument, const Verify& verify) {
  std::optional<Error> last;
  for (attempts_ = 1; attempts_ <= policy_.max_attempts; ++attempts_) {
    phase_ = ReconnectPhase::closing;
    instrument.disconnect();
    phase_ = ReconnectPhase::backing_off;
    asio::steady_timer timer(executor_, policy_.backoff(attempts_));
    co_await timer.async_wait(asio::use_awaitable);
    try {
      phase_ = ReconnectPhase::reopening;
      co_await instrument.connect();
      phase_ = ReconnectPhase::verifying;
      if (verify) co_await verify();
      phase_ = ReconnectPhase::connected;
      log::info("drivers", instrument.id() + ": reconnected after " + std::to_string(attempts_) + " attempt(s)");
      co_return;
    } catch (const Error& e) {
      last = e;
      log::warning("drivers", instrument.id() + ": reconnect attempt " + std::to_string(attempts_) + " failed: " + e.what());
      // An instrument that needs a person will not be fixed by trying again.
      if (!calls_for_reconnect(e)) break;
    }
  }
  phase_ = ReconnectPhase::gave_up;
  ErrorInfo info = last->info();
  info.message = instrument.id() + ": reconnect gave up after " + std::to_string(std::min(attempts_, policy_.max_attempts)) +
                 " attempt(s): " + info.message;
  throw Error(std::move(info));
}

}  // namespace colorlab::drivers
