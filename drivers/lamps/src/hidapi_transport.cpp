#include "colorlab/drivers/hidapi_transport.hpp"

#include <hidapi.h>

#include <cwchar>
#include <mutex>

#include "colorlab/core/error.hpp"

namespace colorlab::drivers {

namespace {

std::string narrow(const wchar_t* w) {
  std::string out;
  if (!w) return out;
  for (; *w; ++w) out.push_back(*w < 0x80 ? static_cast<char>(*w) : '?');
  return out;
}

void ensure_hid_init() {
  static std::once_flag once;
  static int rc = 0;
  std::call_once(once, [] { rc = hid_init(); });
  if (rc != 0) throw Error(ErrorClass::no_comms, "hidapi could not initialise", "is /dev/hidraw* accessible?");
}

bool is_relay_board(const hid_device_info* d) {
  std::string product = narrow(d->product_string);
  return d->vendor_id == kDcttechVendorId && d->product_id == kDcttechProductId &&
         narrow(d->manufacturer_string) == "www.dcttech.com" && product.rfind("USBRelay", 0) == 0;
}

hid_device* dev(void* p) { return static_cast<hid_device*>(p); }

}  // namespace

std::vector<HidDeviceInfo> enumerate_relay_boards() {
  std::vector<HidDeviceInfo> out;
  try {
    ensure_hid_init();
  } catch (const Error&) {
    return out;
  }
  hid_device_info* list = hid_enumerate(kDcttechVendorId, kDcttechProductId);
  for (auto* d = list; d; d = d->next) {
    if (!is_relay_board(d)) continue;
    out.push_back(HidDeviceInfo{d->path ? d->path : "", d->vendor_id, d->product_id, narrow(d->manufacturer_string),
                                narrow(d->product_string), narrow(d->serial_number)});
  }
  hid_free_enumeration(list);
  return out;
}

HidapiTransport::HidapiTransport(std::string path) : path_(std::move(path)) {}

HidapiTransport::~HidapiTransport() { close(); }

void HidapiTransport::open() {
  close();
  ensure_hid_init();
  auto boards = enumerate_relay_boards();
  const HidDeviceInfo* chosen = nullptr;
  for (const auto& b : boards) {
    if (path_.empty() || b.path == path_) {
      chosen = &b;
      break;
    }
  }
  if (!chosen) {
    throw Error(ErrorClass::no_comms,
                path_.empty() ? "no dcttech USB relay board found" : "no dcttech USB relay board at " + path_,
                "check the USB cable; non-root access needs colorlab's udev rule for 16c0:05df (docs/udev-notes.md)");
  }
  info_ = *chosen;
  device_ = hid_open_path(info_.path.c_str());
  if (!device_) {
    throw Error(ErrorClass::no_comms, "cannot open relay board " + info_.path,
                "permission denied is the usual cause: install colorlab's udev rule for hidraw 16c0:05df");
  }
}

void HidapiTransport::close() {
  if (device_) hid_close(dev(device_));
  device_ = nullptr;
}

void HidapiTransport::send_feature_report(const std::vector<std::uint8_t>& report) {
  if (!device_) throw Error(ErrorClass::no_comms, "relay board is not open");
  if (hid_send_feature_report(dev(device_), report.data(), report.size()) < 0) {
    std::string why = narrow(hid_error(dev(device_)));
    throw Error(ErrorClass::no_comms, "relay board " + info_.path + ": set feature report failed: " + why,
                "the board may have been unplugged");
  }
}

std::vector<std::uint8_t> HidapiTransport::get_feature_report(std::uint8_t report_number, std::size_t data_length) {
  if (!device_) throw Error(ErrorClass::no_comms, "relay board is not open");
  std::vector<std::uint8_t> buf(data_length + 1, 0);
  buf[0] = report_number;
  int n = hid_get_feature_report(dev(device_), buf.data(), buf.size());
  if (n < 0) {
    std::string why = narrow(hid_error(dev(device_)));
    throw Error(ErrorClass::no_comms, "relay board " + info_.path + ": get feature report failed: " + why,
                "the board may have been unplugged");
  }
  // On hidraw the board's unnumbered report comes back without a report-number prefix, so the data
  // starts at buf[0] (usbrelay's hidapi code relies on this); the libusb backend would prefix it.
  buf.resize(data_length);
  return buf;
}

}  // namespace colorlab::drivers
