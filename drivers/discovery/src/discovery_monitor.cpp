#include "colorlab/drivers/discovery_monitor.hpp"

#include <libusb.h>

#include <filesystem>
#include <system_error>

#include "colorlab/core/error.hpp"
#include "colorlab/core/log.hpp"

namespace colorlab::drivers {

struct UsbHotplug::Impl {
  libusb_context* ctx = nullptr;
  libusb_hotplug_callback_handle handle = 0;
  std::function<void()> on_event;
};

namespace {

int LIBUSB_CALL hotplug_callback(libusb_context*, libusb_device*, libusb_hotplug_event, void* user) {
  auto* impl = static_cast<UsbHotplug::Impl*>(user);
  if (impl->on_event) impl->on_event();
  return 0;  // stay registered
}

}  // namespace

std::string UsbHotplug::unavailable_reason() {
  std::error_code ec;
  // Without usbfs libusb has nothing to watch (CI machines and containers have no USB at all).
  if (!std::filesystem::exists("/dev/bus/usb", ec)) return "no /dev/bus/usb on this machine";
  if (!libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG)) return "libusb was built without hotplug support";
  return {};
}

UsbHotplug::UsbHotplug(std::function<void()> on_event) : impl_(std::make_unique<Impl>()) {
  if (auto why = unavailable_reason(); !why.empty()) throw Error(ErrorClass::unsupported, "USB hotplug unavailable: " + why);
  impl_->on_event = std::move(on_event);
  if (int rc = libusb_init(&impl_->ctx); rc != 0) {
    throw Error(ErrorClass::unsupported, std::string("libusb_init failed: ") + libusb_error_name(rc));
  }
  int rc = libusb_hotplug_register_callback(
      impl_->ctx, static_cast<libusb_hotplug_event>(LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED | LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT),
      static_cast<libusb_hotplug_flag>(0), LIBUSB_HOTPLUG_MATCH_ANY, LIBUSB_HOTPLUG_MATCH_ANY, LIBUSB_HOTPLUG_MATCH_ANY,
      hotplug_callback, impl_.get(), &impl_->handle);
  if (rc != LIBUSB_SUCCESS) {
    libusb_exit(impl_->ctx);
    throw Error(ErrorClass::unsupported, std::string("libusb hotplug registration failed: ") + libusb_error_name(rc));
  }
}

UsbHotplug::~UsbHotplug() {
  if (impl_ && impl_->ctx) {
    libusb_hotplug_deregister_callback(impl_->ctx, impl_->handle);
    libusb_exit(impl_->ctx);
  }
}

void UsbHotplug::handle_events() {
  timeval zero{0, 0};
  libusb_handle_events_timeout_completed(impl_->ctx, &zero, nullptr);
}

DiscoveryMonitor::DiscoveryMonitor(boost::asio::any_io_executor executor, Discovery& discovery, std::chrono::milliseconds tick,
                                   int ticks_per_rescan)
    : discovery_(discovery), timer_(executor), tick_(tick), ticks_per_rescan_(std::max(1, ticks_per_rescan)) {
  try {
    hotplug_ = std::make_unique<UsbHotplug>([this] { dirty_ = true; });
    hotplug_status_ = "libusb hotplug";
  } catch (const Error& e) {
    hotplug_status_ = std::string("periodic re-scan (") + e.what() + ")";
    log::info("discovery", hotplug_status_);
  }
}

DiscoveryMonitor::~DiscoveryMonitor() { stop(); }

void DiscoveryMonitor::start() {
  if (running_) return;
  running_ = true;
  dirty_ = true;
  schedule();
}

void DiscoveryMonitor::stop() {
  running_ = false;
  timer_.cancel();
}

void DiscoveryMonitor::schedule() {
  if (!running_) return;
  if (hotplug_) hotplug_->handle_events();
  if (dirty_ || ++ticks_ % ticks_per_rescan_ == 0) {
    dirty_ = false;
    ++scans_;
    try {
      discovery_.poll();
    } catch (const std::exception& e) {
      log::warning("discovery", std::string("scan failed: ") + e.what());
    }
  }
  timer_.expires_after(tick_);
  timer_.async_wait([this](boost::system::error_code ec) {
    if (!ec) schedule();
  });
}

}  // namespace colorlab::drivers
