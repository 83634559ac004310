#pragma once
// The reconnect state machine every driver shares: close the link, back off, reopen, re-verify the
// instrument's identity (connect() does that) and, if given, its calibration. Bounded: after
// `max_attempts` it gives up with the last error, so an unattended night never spins forever.
#include <chrono>
#include <functional>
#include <string_view>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/awaitable.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/instrument.hpp"

namespace colorlab::drivers {

struct ReconnectPolicy {
  int max_attempts = 5;
  std::chrono::milliseconds initial_backoff{250};
  double backoff_factor = 2.0;
  std::chrono::milliseconds max_backoff{8000};

  std::chrono::milliseconds backoff(int attempt) const;  // attempt 1 → initial_backoff
};

enum class ReconnectPhase {
  idle,
  closing,
  backing_off,
  reopening,
  verifying,
  connected,
  gave_up
};
std::string_view to_string(ReconnectPhase p);

// Errors after which reopening the link can help (the link is gone or the device stopped answering).
bool calls_for_reconnect(const Error& e);

class Reconnector {
 public:
  using Verify = std::function<boost::asio::awaitable<void>()>;

  Reconnector(boost::asio::any_io_executor executor, ReconnectPolicy policy = {});

  // Throws the last Error (class unchanged, message prefixed) once the attempts are used up.
  // `verify` must outlive the operation (pass a named object: GCC 12 mishandles temporaries in co_await).
  boost::asio::awaitable<void> reconnect(Instrument& instrument, const Verify& verify);
  boost::asio::awaitable<void> reconnect(Instrument& instrument);  // identity check by connect() only

  ReconnectPhase phase() const { return phase_; }
  int attempts_used() const { return attempts_; }
  const ReconnectPolicy& policy() const { return policy_; }

 private:
  boost::asio::any_io_executor executor_;
  ReconnectPolicy policy_;
  ReconnectPhase phase_ = ReconnectPhase::idle;
  int attempts_ = 0;
};

}  // namespace colorlab::drivers
