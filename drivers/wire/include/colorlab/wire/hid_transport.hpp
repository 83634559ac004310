#pragma once
// The few HID operations the relay board needs, behind an interface: the production side is
// hidapi (hidapi_transport.hpp); tests use the scripted board in sim/relay, because no virtual HID
// device can be created on the build machines. It lives in drivers/wire/ so that board can implement it
// without sim/ depending on the lamps driver; it stays in colorlab::drivers, the namespace its users speak.
#include <cstdint>
#include <string>
#include <vector>

namespace colorlab::drivers {

struct HidDeviceInfo {
  std::string path;  // /dev/hidrawN
  std::uint16_t vendor_id = 0;
  std::uint16_t product_id = 0;
  std::string manufacturer;
  std::string product;
  std::string serial;
};

class HidTransport {
 public:
  virtual ~HidTransport() = default;

  // All of these throw colorlab::Error: no_comms when the device is absent or was unplugged.
  virtual void open() = 0;
  virtual void close() = 0;
  virtual bool is_open() const = 0;
  virtual HidDeviceInfo info() const = 0;
  // report[0] is the report number (0 for boards without numbered reports), then the data bytes.
  virtual void send_feature_report(const std::vector<std::uint8_t>& report) = 0;
  // The data bytes only: any report-number prefix the backend adds is stripped by the transport.
  virtual std::vector<std::uint8_t> get_feature_report(std::uint8_t report_number, std::size_t data_length) = 0;
};

}  // namespace colorlab::drivers
