#include "colorlab/drivers/enttec_dmx.hpp"

#include <cmath>
#include <cstdio>

#include <boost/asio/steady_timer.hpp>
#include <boost/asio/use_awaitable.hpp>

#include "colorlab/core/log.hpp"

namespace colorlab::drivers {

namespace asio = boost::asio;
namespace en = colorlab::wire::enttec;

namespace {

std::string as_bytes(const en::Bytes& b) { return std::string(b.begin(), b.end()); }

std::string bcd_text(std::uint32_t bcd) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%08X", bcd);
  return buf;
}

}  // namespace

EnttecDmx::EnttecDmx(asio::any_io_executor executor, EnttecDmxOptions options)
    : options_(std::move(options)),
      executor_(executor),
      link_(executor, options_.port),
      reconnector_(executor, options_.reconnect),
      universe_(std::clamp<std::size_t>(options_.slots, 1, en::kMaxSlots), 0) {
  if (options_.dimmer_channel < 0 || options_.dimmer_channel > static_cast<int>(universe_.size())) {
    throw Error(ErrorClass::bad_parameter, "dimmer channel " + std::to_string(options_.dimmer_channel) + " is outside 1.." +
                                               std::to_string(universe_.size()));
  }
  for (const auto& name : options_.lamps.names()) {
    if (options_.lamps.output(name) > static_cast<int>(universe_.size())) {
      throw Error(ErrorClass::bad_parameter, "lamp '" + name + "' is on channel " + std::to_string(options_.lamps.output(name)) +
                                                 " beyond the " + std::to_string(universe_.size()) + " slots sent");
    }
    if (options_.lamps.output(name) == options_.dimmer_channel) {
      throw Error(ErrorClass::bad_parameter, "lamp '" + name + "' shares channel " + std::to_string(options_.dimmer_channel) +
                                                 " with the dimmer");
    }
  }
  if (options_.ramp_per_second < 0 || options_.frame_interval.count() <= 0) {
    throw Error(ErrorClass::bad_parameter, "ramp rate must be >= 0 and the frame interval > 0");
  }
}

Identity EnttecDmx::identity() const {
  char fw[16];
  std::snprintf(fw, sizeof fw, "%u.%u", static_cast<unsigned>(params_.firmware >> 8), static_cast<unsigned>(params_.firmware & 0xFF));
  return Identity{"dmx", "Enttec DMX USB Pro", serial_ ? bcd_text(serial_) : "", serial_ ? fw : "", options_.port,
                  options_.simulated};
}

void EnttecDmx::fail(const Error& e) {
  last_problem_ = std::string(e.what()) + (e.hint().empty() ? "" : " (" + e.hint() + ")");
  switch (e.cls()) {
    case ErrorClass::bad_parameter:
    case ErrorClass::conflict: break;
    case ErrorClass::no_comms: state_ = InstrumentState::disconnected; break;
    default: state_ = InstrumentState::fault; break;
  }
  throw e;
}

asio::awaitable<en::Frame> EnttecDmx::read_frame(std::chrono::steady_clock::time_point deadline) {
  auto left = [&] {
    auto d = deadline - std::chrono::steady_clock::now();
    return d > SerialLink::Duration::zero() ? d : SerialLink::Duration(1);
  };
  for (;;) {
    // Resynchronise on the start byte: anything before it is line noise.
    std::string b = co_await link_.read_exactly(1, left());
    if (static_cast<std::uint8_t>(b[0]) != en::kStart) continue;
    std::string head = co_await link_.read_exactly(3, left());
    std::size_t len = static_cast<std::uint8_t>(head[1]) | (static_cast<std::size_t>(static_cast<std::uint8_t>(head[2])) << 8);
    if (len > en::kMaxPayload) continue;  // not a frame start after all
    std::string rest = co_await link_.read_exactly(len + 1, left());
    std::string whole = b + head + rest;
    try {
      co_return en::decode_frame(std::span(reinterpret_cast<const std::uint8_t*>(whole.data()), whole.size()));
    } catch (const Error& e) {
      throw link_.make_error(e.cls(), e.info().message, "the widget's reply was corrupted; the driver retries");
    }
  }
}

asio::awaitable<en::Frame> EnttecDmx::request(const en::Bytes& frame, std::uint8_t reply_label, std::string_view what) {
  std::optional<Error> last;
  for (int attempt = 1; attempt <= options_.attempts; ++attempt) {
    link_.discard_input();
    try {
      co_await link_.write(as_bytes(frame), options_.reply_timeout);
      auto deadline = std::chrono::steady_clock::now() + options_.reply_timeout;
      for (;;) {
        auto f = co_await read_frame(deadline);
        if (f.label == reply_label) co_return f;
        log::debug("dmx", "ignoring widget frame with label " + std::to_string(f.label));
      }
    } catch (const Error& e) {
      if (e.cls() != ErrorClass::timeout && e.cls() != ErrorClass::coms_fail && e.cls() != ErrorClass::protocol_error) throw;
      last = e;
    }
  }
  ErrorInfo info = last->info();
  info.message = options_.port + ": " + std::string(what) + " failed " + std::to_string(options_.attempts) + " times: " + info.message;
  if (info.hint.empty()) info.hint = "check that this port is an Enttec DMX USB Pro and that it is powered";
  throw Error(std::move(info));
}

asio::awaitable<void> EnttecDmx::connect() {
  state_ = InstrumentState::initialising;
  try {
    SerialSettings s;  // an FTDI VCOM: the speed is a dummy value, 8N1 as OLA opens it
    s.baud = 115200;
    link_.open(s);
    auto serial = co_await request(en::get_serial_request(), en::label::GetSerialNumber, "serial number request (label 10)");
    auto params = co_await request(en::get_parameters_request(), en::label::GetWidgetParameters, "parameter request (label 3)");
    try {
      serial_ = en::decode_serial_reply(serial);
      params_ = en::decode_parameters_reply(params);
    } catch (const Error& e) {
      throw link_.make_error(ErrorClass::protocol_error, e.info().message, "this does not look like a DMX USB Pro");
    }
    if ((params_.firmware >> 8) < 1 || (params_.firmware >> 8) > 3) {
      throw link_.make_error(ErrorClass::unsupported, "unknown widget firmware type " + std::to_string(params_.firmware >> 8),
                             "expected DMX (1), RDM (2) or sniffer (3) firmware");
    }
    // After a reconnect the widget restarts dark: put back what the lamps were doing.
    if (packets_ > 0) co_await send_universe();
    state_ = InstrumentState::ready;
    last_problem_.clear();
  } catch (const Error& e) {
    link_.close();
    fail(e);
  }
}

void EnttecDmx::disconnect() {
  link_.close();
  state_ = InstrumentState::disconnected;
}

asio::awaitable<void> EnttecDmx::send_universe() {
  co_await link_.write(as_bytes(en::send_dmx_request(universe_)), options_.reply_timeout);
  ++packets_;
}

std::vector<std::string> EnttecDmx::lamp_names() const { return options_.lamps.names(); }

int EnttecDmx::channel_of(const std::string& lamp) const {
  if (lamp == "dimmer") {
    if (options_.dimmer_channel == 0) throw Error(ErrorClass::bad_parameter, options_.id + " has no dimmer channel configured");
    return options_.dimmer_channel;
  }
  return options_.lamps.output(lamp);
}

asio::awaitable<void> EnttecDmx::ramp_to(const std::map<int, std::uint8_t>& targets) {
  std::map<int, std::uint8_t> from;
  int max_delta = 0;
  for (const auto& [ch, v] : targets) {
    from[ch] = universe_[static_cast<std::size_t>(ch - 1)];
    max_delta = std::max(max_delta, std::abs(static_cast<int>(v) - static_cast<int>(from[ch])));
  }
  int steps = 1;
  if (options_.ramp_per_second > 0 && max_delta > 0) {
    double seconds = (max_delta / 255.0) / options_.ramp_per_second;
    steps = std::max(1, static_cast<int>(std::ceil(seconds * 1000.0 / static_cast<double>(options_.frame_interval.count()))));
  }
  asio::steady_timer timer(executor_);
  auto next = std::chrono::steady_clock::now();
  for (int k = 1; k <= steps; ++k) {
    for (const auto& [ch, v] : targets) {
      double f = static_cast<double>(k) / steps;
      universe_[static_cast<std::size_t>(ch - 1)] =
          static_cast<std::uint8_t>(std::lround(from[ch] + f * (static_cast<int>(v) - static_cast<int>(from[ch]))));
    }
    co_await send_universe();
    if (k < steps) {
      next += options_.frame_interval;
      timer.expires_at(next);
      co_await timer.async_wait(asio::use_awaitable);
    }
  }
  if (options_.settle.count() > 0) {
    timer.expires_after(options_.settle);
    co_await timer.async_wait(asio::use_awaitable);
  }
}

asio::awaitable<void> EnttecDmx::ramp_with_reconnect(const std::map<int, std::uint8_t>& targets) {
  if (state_ == InstrumentState::busy) throw Error(ErrorClass::conflict, options_.id + " is busy with another change");
  if (!link_.is_open()) co_await connect();
  state_ = InstrumentState::busy;
  try {
    bool lost = false;
    try {
      co_await ramp_to(targets);
    } catch (const Error& e) {
      if (!calls_for_reconnect(e)) throw;
      log::warning("dmx", options_.id + ": " + e.what() + "; reconnecting");
      lost = true;
    }
    if (lost) {
      co_await reconnector_.reconnect(*this);
      state_ = InstrumentState::busy;
      co_await ramp_to(targets);
    }
    state_ = InstrumentState::ready;
  } catch (const Error& e) {
    fail(e);
  }
}

asio::awaitable<void> EnttecDmx::set_lamps(std::vector<std::string> on) {
  std::vector<int> lit;
  try {
    lit = options_.lamps.outputs_for(on);
  } catch (const Error& e) {
    fail(e);
  }
  // Break before make: ramp the others down first so two lamps never overlap.
  std::map<int, std::uint8_t> off, up;
  for (const auto& name : options_.lamps.names()) {
    int ch = options_.lamps.output(name);
    bool want = std::find(lit.begin(), lit.end(), ch) != lit.end();
    if (!want && universe_[static_cast<std::size_t>(ch - 1)] != 0) off[ch] = 0;
    if (want) up[ch] = 255;
  }
  if (!off.empty()) co_await ramp_with_reconnect(off);
  co_await ramp_with_reconnect(up);
}

std::vector<std::string> EnttecDmx::lamps_on() const {
  std::vector<std::string> out;
  for (const auto& name : options_.lamps.names()) {
    if (universe_[static_cast<std::size_t>(options_.lamps.output(name) - 1)] > 0) out.push_back(name);
  }
  return out;
}

asio::awaitable<void> EnttecDmx::set_level(const std::string& lamp, double level) {
  int ch = 0;
  try {
    if (!std::isfinite(level) || level < 0 || level > 1) {
      throw Error(ErrorClass::bad_parameter, "level " + std::to_string(level) + " for '" + lamp + "' is outside 0..1");
    }
    ch = channel_of(lamp);
    if (lamp != "dimmer" && level > 0) {
      std::vector<std::string> lit = lamps_on();
      lit.erase(std::remove(lit.begin(), lit.end(), lamp), lit.end());
      lit.push_back(lamp);
      options_.lamps.outputs_for(lit);  // refuses a second lamp unless allowed
    }
  } catch (const Error& e) {
    fail(e);
  }
  std::map<int, std::uint8_t> target;
  target[ch] = static_cast<std::uint8_t>(std::lround(level * 255.0));
  co_await ramp_with_reconnect(target);
}

double EnttecDmx::level(const std::string& lamp) const {
  return universe_[static_cast<std::size_t>(channel_of(lamp) - 1)] / 255.0;
}

}  // namespace colorlab::drivers
