#pragma once
// HidTransport over a Unix socket: how the simulated lab's relay board is reached, since no virtual
// HID device can exist on these machines. Each HID operation is one JSON line out and one back
// (docs/simulator.md, "HID relay socket"); the feature reports travel as hex, byte for byte as
// hidapi would pass them, so HidRelay runs unchanged above it. Written from the document, not from
// the simulator's code. Calls block for at most `reply_timeout` (HID transfers are a few ms).
#include <chrono>
#include <memory>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "colorlab/wire/hid_transport.hpp"

namespace colorlab::drivers {

class UnixLineClient;

class SocketHidTransport final : public HidTransport {
 public:
  SocketHidTransport(std::string socket_path, std::chrono::milliseconds reply_timeout = std::chrono::milliseconds(1000));
  ~SocketHidTransport() override;

  void open() override;
  void close() override;
  bool is_open() const override;
  HidDeviceInfo info() const override { return info_; }
  void send_feature_report(const std::vector<std::uint8_t>& report) override;
  std::vector<std::uint8_t> get_feature_report(std::uint8_t report_number, std::size_t data_length) override;

 private:
  nlohmann::json call(const nlohmann::json& request);

  std::string socket_path_;
  std::chrono::milliseconds reply_timeout_;
  std::unique_ptr<UnixLineClient> link_;
  HidDeviceInfo info_;
};

}  // namespace colorlab::drivers
