#include "colorlab/drivers/serial_link.hpp"

#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <termios.h>

#include <boost/asio/redirect_error.hpp>
#include <boost/asio/write.hpp>
#include <boost/asio/use_awaitable.hpp>

#include "colorlab/core/log.hpp"

namespace colorlab::drivers {

namespace asio = boost::asio;
using boost::system::error_code;

std::chrono::nanoseconds SerialSettings::byte_time() const {
  unsigned bits = 1 + data_bits + (parity == Parity::none ? 0 : 1) + stop_bits;
  return std::chrono::nanoseconds(static_cast<long long>(1e9 * bits / baud));
}

namespace {

// UNIX98 pty slaves have majors 136..143 on Linux.
bool is_pty_fd(int fd) {
  struct stat st {};
  if (fstat(fd, &st) != 0 || !S_ISCHR(st.st_mode)) return false;
  unsigned maj = major(st.st_rdev);
  return maj >= 136 && maj <= 143;
}

std::string transport_code(const error_code& ec) {
  return std::string(ec.category().name()) + ":" + std::to_string(ec.value());
}

}  // namespace

std::string describe(const SerialSettings& s) {
  const char parity = s.parity == Parity::even ? 'E' : s.parity == Parity::odd ? 'O'
                                                                               : 'N';
  const char* flow = s.flow == FlowControl::hardware ? "rts/cts" : s.flow == FlowControl::software ? "xon/xoff"
                                                                                                   : "none";
  return std::to_string(s.baud) + " " + std::to_string(s.data_bits) + parity + std::to_string(s.stop_bits) + " " + flow;
}

SerialLink::SerialLink(asio::any_io_executor executor, std::string path)
    : executor_(executor), path_(std::move(path)), timer_(executor) {}

SerialLink::~SerialLink() { close(); }

bool SerialLink::is_open() const { return port_ && port_->is_open(); }

Error SerialLink::make_error(ErrorClass cls, std::string message, std::string hint, std::string device_code,
                             std::string transport_code) const {
  ErrorInfo info;
  info.cls = cls;
  info.message = path_ + ": " + std::move(message);
  info.hint = std::move(hint);
  info.device_code = std::move(device_code);
  info.transport_code = std::move(transport_code);
  info.retryable = cls == ErrorClass::timeout || cls == ErrorClass::coms_fail || cls == ErrorClass::misread;
  info.transcript = transcript_.lines();
  return Error(std::move(info));
}

void SerialLink::open(const SerialSettings& settings) {
  close();
  auto port = std::make_unique<asio::serial_port>(executor_);
  error_code ec;
  port->open(path_, ec);
  if (ec) {
    throw make_error(ErrorClass::no_comms, "cannot open serial port: " + ec.message(),
                     ec == boost::system::errc::permission_denied
                         ? "add the daemon's user to the serial group (dialout/colorlab) or install colorlab's udev rules"
                         : "check the cable, the USB adapter and the configured port path",
                     {}, transport_code(ec));
  }
  port_ = std::move(port);
  is_pty_ = is_pty_fd(port_->native_handle());
  rx_.clear();
  reconfigure(settings);
}

void SerialLink::reconfigure(const SerialSettings& settings) {
  if (!is_open()) throw make_error(ErrorClass::no_comms, "port is not open");
  using SP = asio::serial_port_base;
  error_code ec;
  port_->set_option(SP::baud_rate(settings.baud), ec);
  if (!ec) {
    port_->set_option(SP::stop_bits(settings.stop_bits == 2 ? SP::stop_bits::two : SP::stop_bits::one), ec);
  }
  if (!ec) {
    auto fc = settings.flow == FlowControl::hardware   ? SP::flow_control::hardware
              : settings.flow == FlowControl::software ? SP::flow_control::software
                                                       : SP::flow_control::none;
    port_->set_option(SP::flow_control(fc), ec);
  }
  if (!ec && !is_pty_) {
    port_->set_option(SP::character_size(settings.data_bits), ec);
    if (!ec) {
      auto p = settings.parity == Parity::even  ? SP::parity::even
               : settings.parity == Parity::odd ? SP::parity::odd
                                                : SP::parity::none;
      port_->set_option(SP::parity(p), ec);
    }
  } else if (!ec && (settings.data_bits != 8 || settings.parity != Parity::none)) {
    log::debug("serial", path_ + " is a pty: keeping the forced 8N framing (the protocol's bytes are 7-bit ASCII)");
  }
  if (ec) {
    throw make_error(ErrorClass::no_comms, "cannot apply serial settings: " + ec.message(),
                     "the adapter may not support this speed or framing", {}, transport_code(ec));
  }
  settings_ = settings;
  transcript_.settings(describe(settings) + (is_pty_ ? " (pty)" : ""));
}

void SerialLink::close() {
  if (port_) {
    error_code ignored;
    port_->cancel(ignored);
    port_->close(ignored);
    port_.reset();
  }
  timer_.cancel();
  rx_.clear();
}

void SerialLink::discard_input() {
  rx_.clear();
  if (is_open()) ::tcflush(port_->native_handle(), TCIFLUSH);
}

asio::awaitable<void> SerialLink::write(std::string_view bytes, Duration timeout) {
  if (!is_open()) throw make_error(ErrorClass::no_comms, "write on a closed port", "reconnect the instrument");
  transcript_.sent(bytes);
  timer_.expires_after(timeout);
  timer_.async_wait([port = port_.get()](error_code ec) {
    if (!ec) port->cancel();
  });
  error_code ec;
  co_await asio::async_write(*port_, asio::buffer(bytes.data(), bytes.size()),
                             asio::redirect_error(asio::use_awaitable, ec));
  timer_.cancel();
  if (ec == asio::error::operation_aborted) {
    throw make_error(ErrorClass::timeout, "write did not complete in time",
                     "hardware handshake (RTS/CTS) may be blocking: check the cable and the instrument's power");
  }
  if (ec) throw make_error(ErrorClass::no_comms, "write failed: " + ec.message(), "the link dropped; reconnecting", {}, transport_code(ec));
}

asio::awaitable<void> SerialLink::fill(std::chrono::steady_clock::time_point deadline, std::string_view waiting_for) {
  if (!is_open()) throw make_error(ErrorClass::no_comms, "read on a closed port", "reconnect the instrument");
  if (std::chrono::steady_clock::now() >= deadline) {
    throw make_error(ErrorClass::timeout, "no complete reply (waiting for " + std::string(waiting_for) + ")",
                     "the instrument is silent: check power, cable and remote mode");
  }
  timer_.expires_at(deadline);
  timer_.async_wait([port = port_.get()](error_code ec) {
    if (!ec) port->cancel();
  });
  char chunk[512];
  error_code ec;
  std::size_t n = co_await port_->async_read_some(asio::buffer(chunk), asio::redirect_error(asio::use_awaitable, ec));
  timer_.cancel();
  if (n > 0) {
    transcript_.received(std::string_view(chunk, n));
    rx_.append(chunk, n);
  }
  if (ec == asio::error::operation_aborted) {
    throw make_error(ErrorClass::timeout,
                     "no complete reply (waiting for " + std::string(waiting_for) + ", have " +
                         std::to_string(rx_.size()) + " bytes)",
                     "the instrument is silent: check power, cable and remote mode");
  }
  if (ec) {
    throw make_error(ErrorClass::no_comms, "read failed: " + ec.message(), "the link dropped; reconnecting", {},
                     transport_code(ec));
  }
}

asio::awaitable<std::string> SerialLink::read_until(std::string_view terminator, Duration timeout) {
  auto deadline = std::chrono::steady_clock::now() + timeout;
  std::size_t searched_from = 0;
  for (;;) {
    auto pos = rx_.find(terminator, searched_from);
    if (pos != std::string::npos) {
      std::string line = rx_.substr(0, pos + terminator.size());
      rx_.erase(0, pos + terminator.size());
      co_return line;
    }
    searched_from = rx_.size() >= terminator.size() ? rx_.size() - terminator.size() + 1 : 0;
    co_await fill(deadline, Transcript::escape(terminator));
  }
}

asio::awaitable<std::string> SerialLink::read_exactly(std::size_t count, Duration timeout) {
  auto deadline = std::chrono::steady_clock::now() + timeout;
  while (rx_.size() < count) co_await fill(deadline, std::to_string(count) + " bytes");
  std::string out = rx_.substr(0, count);
  rx_.erase(0, count);
  co_return out;
}

}  // namespace colorlab::drivers
