#include "colorlab/drivers/spectrolino_link.hpp"

#include "colorlab/core/log.hpp"

namespace colorlab::drivers {

namespace asio = boost::asio;

SerialSettings spectrolino_serial_settings(unsigned baud, FlowControl flow) {
  SerialSettings s;
  s.baud = baud;
  s.data_bits = 8;
  s.parity = Parity::none;
  s.stop_bits = 1;
  s.flow = flow;
  return s;
}

SpectrolinoLink::SpectrolinoLink(SerialLink& link, SpectrolinoTimeouts timeouts, int attempts)
    : link_(link), timeouts_(timeouts), attempts_(attempts < 1 ? 1 : attempts) {}

void SpectrolinoLink::rethrow(const Error& e) const {
  ErrorInfo info = e.info();
  Error annotated = link_.make_error(info.cls, info.message, info.hint, info.device_code, info.transport_code);
  ErrorInfo merged = annotated.info();
  merged.retryable = info.retryable || merged.retryable;
  throw Error(std::move(merged));
}

asio::awaitable<std::optional<std::string>> SpectrolinoLink::try_once(const sl::Bytes& body, std::chrono::milliseconds timeout) {
  link_.discard_input();
  ++commands_;
  co_await link_.write(sl::frame_request(body), timeout);
  try {
    co_return co_await link_.read_until("\n", timeout);
  } catch (const Error& e) {
    if (e.cls() != ErrorClass::timeout) throw;
  }
  co_return std::nullopt;
}

asio::awaitable<sl::Bytes> SpectrolinoLink::transact(const sl::Bytes& body, std::chrono::milliseconds timeout,
                                                     std::string_view what, int attempts) {
  if (attempts <= 0) attempts = attempts_;
  std::optional<Error> last;
  for (int attempt = 1; attempt <= attempts; ++attempt) {
    // A late answer to a timed-out command must never be taken for this one's.
    link_.discard_input();
    ++commands_;
    try {
      co_await link_.write(sl::frame_request(body), timeout);
      std::string line = co_await link_.read_until("\n", timeout);
      sl::Bytes answer = sl::unframe_answer(line);
      auto head = sl::answer_head(answer);
      if (!head.scan && head.code == sl::ans::ComError) {
        auto code = sl::ComError::decode(answer).error;
        auto d = sl::describe_com_error(code);
        throw Error(ErrorInfo{d.cls == ErrorClass::coms_fail || !d.known ? ErrorClass::coms_fail : d.cls,
                              std::string(what) + ": the Spectrolino reported COM error " + sl::to_hex(std::vector<std::uint8_t>{code}) +
                                  " (" + std::string(d.meaning) + ")",
                              "the line is noisy or the instrument lost the speed setting; the driver retries and reconnects",
                              "spectrolino-com:" + sl::to_hex(std::vector<std::uint8_t>{code}),
                              {},
                              d.cls == ErrorClass::coms_fail,
                              {}});
      }
      if (head.scan && head.code == sl::scan_ans::ComErrorAnswer) {
        auto code = sl::ScanComErrorAnswer::decode(answer).error;
        auto d = sl::describe_com_error(code);
        throw Error(ErrorInfo{d.cls == ErrorClass::coms_fail || !d.known ? ErrorClass::coms_fail : d.cls,
                              std::string(what) + ": the SpectroScan reported COM error " + sl::to_hex(std::vector<std::uint8_t>{code}) +
                                  " (" + std::string(d.meaning) + ")",
                              "the line is noisy or the table lost the speed setting; the driver retries and reconnects",
                              "spectroscan-com:" + sl::to_hex(std::vector<std::uint8_t>{code}),
                              {},
                              d.cls == ErrorClass::coms_fail,
                              {}});
      }
      co_return answer;
    } catch (const Error& e) {
      if (e.cls() != ErrorClass::timeout && e.cls() != ErrorClass::coms_fail) rethrow(e);
      last = e;
      log::debug("spectrolino", std::string(what) + ": attempt " + std::to_string(attempt) + " failed: " + e.what());
    }
  }
  ErrorInfo info = last->info();
  info.message = std::string(what) + " failed " + std::to_string(attempts) + " times: " + info.message;
  rethrow(Error(std::move(info)));
}

asio::awaitable<SpectrolinoLink::Found> SpectrolinoLink::scan(const std::vector<unsigned>& speeds) {
  std::string tried;
  for (unsigned baud : speeds) {
    tried += (tried.empty() ? "" : ", ") + std::to_string(baud);
    if (!link_.is_open()) {
      link_.open(spectrolino_serial_settings(baud, FlowControl::none));
    } else {
      link_.reconfigure(spectrolino_serial_settings(baud, FlowControl::none));
    }
    // Enough for the probe and its answer at this speed, plus the device's turnaround.
    auto wire = link_.settings().byte_time() * 32;
    auto timeout = timeouts_.probe + std::chrono::duration_cast<std::chrono::milliseconds>(wire);
    auto line = co_await try_once(sl::req::output_status(), timeout);
    if (!line) continue;
    sl::Bytes answer;
    try {
      answer = sl::unframe_answer(*line);
    } catch (const Error&) {
      continue;  // noise at the wrong speed
    }
    auto head = sl::answer_head(answer);
    if (head.scan && head.code == sl::scan_ans::StatusAnswer) co_return Found{SpectrolinoTopology::spectroscan, baud};
    // A stand-alone Spectrolino does not know the D0 record and answers with COM error 26.
    if (!head.scan && head.code == sl::ans::ComError) co_return Found{SpectrolinoTopology::standalone, baud};
  }
  throw link_.make_error(ErrorClass::no_comms, "no Spectrolino or SpectroScan answered at " + tried + " baud",
                         "check power and cable; a SpectroScan must be switched on and its Spectrolino docked");
}

}  // namespace colorlab::drivers
