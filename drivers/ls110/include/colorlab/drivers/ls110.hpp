#pragma once
// Konica Minolta LS-110 luminance meter. 4800 baud, 7E2, no flow control. The meter only
// answers in remote mode (switched on while holding F); a meter that falls silent has dropped
// out of it and needs a person, so silence after retries becomes Error{needs_operator}.
#include <chrono>
#include <memory>
#include <string>

#include <boost/asio/any_io_executor.hpp>

#include "colorlab/drivers/instrument.hpp"
#include "colorlab/drivers/serial_link.hpp"

namespace colorlab::drivers {

struct Ls110Options {
  std::string id = "ls110";
  std::string port;
  bool simulated = false;
  // No published measuring time; PsychoPy waits up to 5 s per reply.
  std::chrono::milliseconds reply_timeout{5000};
  int attempts = 3;  // per command, for timeouts and garbled lines
};

class Ls110 final : public LuminanceMeter {
 public:
  Ls110(boost::asio::any_io_executor executor, Ls110Options options);

  const std::string& id() const override { return options_.id; }
  Identity identity() const override;
  InstrumentState state() const override { return state_; }
  std::vector<Capability> capabilities() const override { return {Capability::luminance}; }
  std::string last_problem() const override { return last_problem_; }

  boost::asio::awaitable<void> connect() override;
  void disconnect() override;
  boost::asio::awaitable<LuminanceReading> measure_luminance() override;

  static SerialSettings serial_settings();
  Transcript& transcript() { return link_.transcript(); }

 private:
  boost::asio::awaitable<std::string> transact(const std::string& command);
  // After a restart the meter may still owe the killed process an answer (a measurement takes
  // ~0.5 s): a reply of the wrong shape — a value to MDS, none to MES — is that late answer, so
  // read the next line instead of taking it for ours.
  boost::asio::awaitable<std::string> transact_expecting(const std::string& command, bool with_value);
  [[noreturn]] void fail(const Error& e);

  Ls110Options options_;
  SerialLink link_;
  InstrumentState state_ = InstrumentState::disconnected;
  std::string last_problem_;
};

}  // namespace colorlab::drivers
