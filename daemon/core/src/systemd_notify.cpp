#include "colorlab/daemon/systemd_notify.hpp"

#include <systemd/sd-daemon.h>

#include <cstdlib>

namespace colorlab::daemon {

SystemdNotifier::SystemdNotifier(boost::asio::io_context& io) : timer_(io) {}

bool SystemdNotifier::under_systemd() const { return std::getenv("NOTIFY_SOCKET") != nullptr; }

void SystemdNotifier::ready(const std::string& s) { sd_notifyf(0, "READY=1\nSTATUS=%s", s.c_str()); }

void SystemdNotifier::status(const std::string& s) { sd_notifyf(0, "STATUS=%s", s.c_str()); }

void SystemdNotifier::stopping() { sd_notify(0, "STOPPING=1"); }

void SystemdNotifier::start_watchdog() {
  uint64_t usec = 0;
  if (sd_watchdog_enabled(0, &usec) <= 0 || usec == 0) return;
  interval_ = std::chrono::microseconds(usec / 2);
  schedule();
}

void SystemdNotifier::schedule() {
  timer_.expires_after(interval_);
  timer_.async_wait([this](boost::system::error_code ec) {
    if (ec) return;
    sd_notify(0, "WATCHDOG=1");
    schedule();
  });
}

}  // namespace colorlab::daemon
