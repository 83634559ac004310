#pragma once
// HidTransport over hidapi (hidraw backend on Linux), and enumeration of dcttech relay boards.
#include <memory>
#include <string>
#include <vector>

#include "colorlab/wire/hid_transport.hpp"

namespace colorlab::drivers {

inline constexpr std::uint16_t kDcttechVendorId = 0x16C0;  // shared V-USB IDs: match the strings too
inline constexpr std::uint16_t kDcttechProductId = 0x05DF;

// Boards whose IDs, manufacturer "www.dcttech.com" and product "USBRelay<N>" all match.
// Returns an empty list (never throws) on machines without USB.
std::vector<HidDeviceInfo> enumerate_relay_boards();

class HidapiTransport final : public HidTransport {
 public:
  // `path` empty: the first relay board found.
  explicit HidapiTransport(std::string path);
  ~HidapiTransport() override;

  void open() override;
  void close() override;
  bool is_open() const override { return device_ != nullptr; }
  HidDeviceInfo info() const override { return info_; }
  void send_feature_report(const std::vector<std::uint8_t>& report) override;
  std::vector<std::uint8_t> get_feature_report(std::uint8_t report_number, std::size_t data_length) override;

 private:
  std::string path_;
  HidDeviceInfo info_;
  void* device_ = nullptr;  // hid_device*, kept out of the header
};

}  // namespace colorlab::drivers
