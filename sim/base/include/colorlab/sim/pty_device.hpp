#pragma once
// Base of every simulated serial instrument: owns a pty, hands received bytes to the protocol
// model, and writes replies after the simulated device time plus the wire time the bytes would
// take at the baud rate the client set (10 bits/byte at 8N1, 11 at 7E2), divided by the time scale.
// Replies leave in order, one at a time, as from a real single-threaded instrument.
#include <atomic>
#include <deque>
#include <memory>
#include <string>
#include <string_view>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <boost/asio/steady_timer.hpp>

#include "colorlab/sim/pty.hpp"

namespace colorlab::sim {

class PtyDevice : public std::enable_shared_from_this<PtyDevice> {
 public:
  PtyDevice(boost::asio::any_io_executor executor, std::string name, double time_scale);
  virtual ~PtyDevice();

  const std::string& name() const { return name_; }
  const std::string& port_path() const { return pty_.slave_path(); }
  LineSettings client_settings() const { return pty_.client_settings(); }

  void start();
  void stop();

  double time_scale() const { return time_scale_.load(); }
  void set_time_scale(double s) { time_scale_ = s; }

 protected:
  virtual void on_bytes(std::string_view bytes) = 0;

  // Queues `bytes` for the client after `device_seconds` of simulated instrument time. The wire
  // time of the `request_bytes` that caused it and of the reply itself is added at the client's baud.
  void reply(std::string bytes, double device_seconds, std::size_t request_bytes);
  // Drops everything queued (a reset or a simulated power cycle).
  void clear_replies();

  boost::asio::any_io_executor executor() const { return executor_; }

 private:
  struct Pending {
    std::string bytes;
    double device_seconds;
    std::size_t request_bytes;
  };
  void read_more();
  void send_next();
  double wire_seconds(std::size_t bytes) const;

  boost::asio::any_io_executor executor_;
  std::string name_;
  std::atomic<double> time_scale_;
  Pty pty_;
  boost::asio::posix::stream_descriptor master_;
  boost::asio::steady_timer timer_;
  std::deque<Pending> queue_;
  bool sending_ = false;
  char buffer_[1024];
};

}  // namespace colorlab::sim
