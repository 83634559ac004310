#pragma once
// sd_notify integration: READY=1 once the database and sockets are up, STATUS= for
// `systemctl status`, STOPPING=1 on shutdown, and WATCHDOG=1 from a timer on the event loop
// itself, so a stalled loop stops the pings and systemd restarts the daemon.
#include <memory>
#include <string>

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>

namespace colorlab::daemon {

class SystemdNotifier {
 public:
  explicit SystemdNotifier(boost::asio::io_context& io);
  void ready(const std::string& status);
  void status(const std::string& status);
  void stopping();
  // Starts pinging at half of WatchdogSec when the service manager asked for a watchdog.
  void start_watchdog();
  bool under_systemd() const;

 private:
  void schedule();
  boost::asio::steady_timer timer_;
  std::chrono::microseconds interval_{0};
};

}  // namespace colorlab::daemon
