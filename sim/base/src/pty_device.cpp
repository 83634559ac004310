#include "colorlab/sim/pty_device.hpp"

#include <boost/asio/write.hpp>

#include "colorlab/core/log.hpp"

namespace colorlab::sim {

namespace asio = boost::asio;

PtyDevice::PtyDevice(asio::any_io_executor executor, std::string name, double time_scale)
    : executor_(executor), name_(std::move(name)), time_scale_(time_scale), master_(executor), timer_(executor) {
  master_.assign(pty_.release_master());
}

PtyDevice::~PtyDevice() = default;

void PtyDevice::start() { read_more(); }

void PtyDevice::stop() {
  boost::system::error_code ignored;
  timer_.cancel();
  master_.cancel(ignored);
}

void PtyDevice::read_more() {
  master_.async_read_some(asio::buffer(buffer_), [self = shared_from_this()](boost::system::error_code ec, std::size_t n) {
    if (ec == asio::error::operation_aborted) return;
    if (ec) {
      // EIO while no client holds the slave is impossible (we hold it); anything else ends the device.
      log::warning("sim", self->name_ + ": pty read failed: " + ec.message());
      return;
    }
    self->on_bytes(std::string_view(self->buffer_, n));
    self->read_more();
  });
}

double PtyDevice::wire_seconds(std::size_t bytes) const {
  auto s = client_settings();
  if (s.baud == 0) return 0;
  return static_cast<double>(bytes) * s.bits_per_byte() / s.baud;
}

void PtyDevice::reply(std::string bytes, double device_seconds, std::size_t request_bytes) {
  queue_.push_back(Pending{std::move(bytes), device_seconds, request_bytes});
  if (!sending_) send_next();
}

void PtyDevice::clear_replies() {
  queue_.clear();
  timer_.cancel();
  sending_ = false;
}

void PtyDevice::send_next() {
  if (queue_.empty()) {
    sending_ = false;
    return;
  }
  sending_ = true;
  const Pending& p = queue_.front();
  double sim_seconds = p.device_seconds + wire_seconds(p.request_bytes + p.bytes.size());
  double real_seconds = sim_seconds / std::max(time_scale_.load(), 1e-9);
  timer_.expires_after(std::chrono::duration_cast<asio::steady_timer::duration>(std::chrono::duration<double>(real_seconds)));
  timer_.async_wait([self = shared_from_this()](boost::system::error_code ec) {
    if (ec || self->queue_.empty()) return;
    auto bytes = std::make_shared<std::string>(std::move(self->queue_.front().bytes));
    self->queue_.pop_front();
    asio::async_write(self->master_, asio::buffer(*bytes), [self, bytes](boost::system::error_code wec, std::size_t) {
      if (wec && wec != asio::error::operation_aborted) {
        log::warning("sim", self->name_ + ": pty write failed: " + wec.message());
      }
      self->send_next();
    });
  });
}

}  // namespace colorlab::sim
