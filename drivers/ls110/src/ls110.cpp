#include "colorlab/drivers/ls110.hpp"

#include <boost/asio/steady_timer.hpp>
#include <boost/asio/this_coro.hpp>
#include <boost/asio/use_awaitable.hpp>

#include "colorlab/core/log.hpp"
#include "colorlab/wire/ls110_protocol.hpp"

namespace colorlab::drivers {

namespace asio = boost::asio;

SerialSettings Ls110::serial_settings() {
  SerialSettings s;
  s.baud = 4800;
  s.data_bits = 7;
  s.parity = Parity::even;
  s.stop_bits = 2;
  s.flow = FlowControl::none;
  return s;
}

Ls110::Ls110(asio::any_io_executor executor, Ls110Options options)
    : options_(std::move(options)), link_(executor, options_.port) {}

Identity Ls110::identity() const {
  // The meter has no identification command; model and port are what we know.
  return Identity{"ls110", "Konica Minolta LS-110", "", "", options_.port, options_.simulated};
}

void Ls110::fail(const Error& e) {
  last_problem_ = e.info().message + (e.hint().empty() ? "" : " (" + e.hint() + ")");
  switch (e.cls()) {
    case ErrorClass::needs_operator: state_ = InstrumentState::needs_operator; break;
    case ErrorClass::misread:
    case ErrorClass::bad_parameter: state_ = InstrumentState::ready; break;
    case ErrorClass::no_comms: state_ = InstrumentState::disconnected; break;
    default: state_ = InstrumentState::fault; break;
  }
  throw e;
}

asio::awaitable<std::string> Ls110::transact(const std::string& command) {
  std::optional<Error> last;
  for (int attempt = 1; attempt <= options_.attempts; ++attempt) {
    // A late reply to an earlier, timed-out command must never be taken for this one.
    link_.discard_input();
    try {
      co_await link_.write(command, options_.reply_timeout);
      std::string line = co_await link_.read_until(wire::ls110::kTerminator, options_.reply_timeout);
      co_return line;
    } catch (const Error& e) {
      if (e.cls() != ErrorClass::timeout) throw;
      last = e;
      log::debug("ls110", "attempt " + std::to_string(attempt) + " timed out");
    }
  }
  ErrorInfo info = last->info();
  info.cls = ErrorClass::needs_operator;
  info.message = options_.port + ": LS-110 did not answer " + std::to_string(options_.attempts) +
                 " times: the meter is off or has left remote mode";
  info.hint = "power-cycle the LS-110 while holding F until '[' shows at the bottom right of the display";
  info.retryable = false;
  throw Error(std::move(info));
}

asio::awaitable<std::string> Ls110::transact_expecting(const std::string& command, bool with_value) {
  std::string line = co_await transact(command);
  for (int late = 0; late < 2; ++late) {
    wire::ls110::Reply reply;
    try {
      reply = wire::ls110::parse_reply(line);
    } catch (const Error&) {
      co_return line;  // garbled: the caller decides
    }
    if (!reply.ok || reply.value.has_value() == with_value) co_return line;
    log::debug("ls110", "discarding a late reply to an earlier command: " + line.substr(0, line.size() - 2));
    line = co_await link_.read_until(wire::ls110::kTerminator, options_.reply_timeout);
  }
  co_return line;
}

asio::awaitable<void> Ls110::connect() {
  state_ = InstrumentState::initialising;
  try {
    link_.open(serial_settings());
    // Absolute mode; any OK proves the meter is there and in remote mode.
    std::string line = co_await transact_expecting(wire::ls110::command_set_mode(4), false);
    auto reply = wire::ls110::parse_reply(line);
    if (!reply.ok) {
      auto code = wire::ls110::lookup_error(reply.error_code);
      throw link_.make_error(code.cls, "LS-110 refused MDS,04: " + code.meaning, code.hint, code.code);
    }
    state_ = InstrumentState::ready;
    last_problem_.clear();
  } catch (const Error& e) {
    fail(e);
  }
}

void Ls110::disconnect() {
  link_.close();
  state_ = InstrumentState::disconnected;
}

asio::awaitable<LuminanceReading> Ls110::measure_luminance() {
  if (state_ == InstrumentState::busy) {
    throw Error(ErrorClass::conflict, options_.id + " is busy with another measurement");
  }
  // A campaign may start while the daemon is still connecting: wait for that exchange to finish
  // rather than interleave our bytes with it on the same line.
  auto give_up = std::chrono::steady_clock::now() + options_.reply_timeout * (options_.attempts + 1);
  while (state_ == InstrumentState::initialising && std::chrono::steady_clock::now() < give_up) {
    boost::asio::steady_timer pause(co_await boost::asio::this_coro::executor, std::chrono::milliseconds(20));
    co_await pause.async_wait(boost::asio::use_awaitable);
  }
  if (!link_.is_open() || state_ == InstrumentState::disconnected) co_await connect();
  state_ = InstrumentState::busy;
  try {
    for (int attempt = 1;; ++attempt) {
      std::string line = co_await transact_expecting(wire::ls110::command_measure(), true);
      wire::ls110::Reply reply;
      try {
        reply = wire::ls110::parse_reply(line);
      } catch (const Error& e) {
        if (attempt < options_.attempts) continue;  // garbled line: measure again
        throw link_.make_error(e.cls(), e.info().message, e.hint());
      }
      if (!reply.ok) {
        auto code = wire::ls110::lookup_error(reply.error_code);
        throw link_.make_error(code.cls, "LS-110 " + code.code + ": " + code.meaning, code.hint, code.code);
      }
      if (!reply.value) throw link_.make_error(ErrorClass::protocol_error, "LS-110 answered MES without a value");
      state_ = InstrumentState::ready;
      last_problem_.clear();
      co_return LuminanceReading{*reply.value, "cd/m2", std::chrono::system_clock::now(), line.substr(0, line.size() - 2)};
    }
  } catch (const Error& e) {
    fail(e);
  }
}

}  // namespace colorlab::drivers
