#pragma once
// Keeps a Discovery current on the daemon's executor: libusb hotplug events (where the machine has
// USB) trigger an immediate re-scan; without hotplug, or as a safety net, it re-scans periodically.
// Subscribers of the Discovery hear about instruments that come and go.
#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/steady_timer.hpp>

#include "colorlab/drivers/discovery.hpp"

namespace colorlab::drivers {

class UsbHotplug {
 public:
  // Empty when hotplug works here; otherwise why not (no /dev/bus/usb, libusb without hotplug...).
  static std::string unavailable_reason();
  // Throws Error{unsupported} with unavailable_reason() when hotplug cannot be used.
  explicit UsbHotplug(std::function<void()> on_event);
  ~UsbHotplug();
  UsbHotplug(const UsbHotplug&) = delete;
  UsbHotplug& operator=(const UsbHotplug&) = delete;
  // Non-blocking: runs the callbacks of pending USB events.
  void handle_events();

  struct Impl;  // public so libusb's C callback can reach it; defined only in the .cpp

 private:
  std::unique_ptr<Impl> impl_;
};

class DiscoveryMonitor {
 public:
  DiscoveryMonitor(boost::asio::any_io_executor executor, Discovery& discovery,
                   std::chrono::milliseconds tick = std::chrono::milliseconds(250), int ticks_per_rescan = 8);
  ~DiscoveryMonitor();

  void start();
  void stop();
  bool hotplug_active() const { return hotplug_ != nullptr; }
  const std::string& hotplug_status() const { return hotplug_status_; }
  int scans() const { return scans_; }

 private:
  void schedule();

  Discovery& discovery_;
  boost::asio::steady_timer timer_;
  std::chrono::milliseconds tick_;
  int ticks_per_rescan_;
  std::unique_ptr<UsbHotplug> hotplug_;
  std::string hotplug_status_;
  bool dirty_ = true;
  bool running_ = false;
  int ticks_ = 0;
  int scans_ = 0;
};

}  // namespace colorlab::drivers
