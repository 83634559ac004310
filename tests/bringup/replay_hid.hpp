#pragma once
// The device side of a relay board's recorded transcript ("transport": "hid"), played as a
// HidTransport: each SET_REPORT must carry the recorded host bytes, each GET_REPORT must ask for the
// recorded report number and gets the recorded answer. Anything else is a mismatch, kept with its
// position and thrown to the driver as no_comms, so the replay fails instead of feeding wrong bytes.
#include <memory>
#include <string>
#include <vector>

#include "colorlab/bringup/recording.hpp"
#include "colorlab/wire/hid_transport.hpp"

namespace colorlab::test {

class ReplayHidTransport : public drivers::HidTransport {
 public:
  ReplayHidTransport(std::vector<bringup::ByteEvent> events, drivers::HidDeviceInfo info);

  void open() override { open_ = true; }
  void close() override { open_ = false; }
  bool is_open() const override { return open_; }
  drivers::HidDeviceInfo info() const override { return info_; }
  void send_feature_report(const std::vector<std::uint8_t>& report) override;
  std::vector<std::uint8_t> get_feature_report(std::uint8_t report_number, std::size_t data_length) override;

  // Shared with the replay, which keeps reading them after the driver (the owner) is gone.
  struct Progress {
    std::size_t position = 0;
    std::size_t size = 0;
    std::string mismatch;
  };
  std::shared_ptr<Progress> progress() const { return progress_; }

 private:
  void expect_host(std::string_view bytes);
  [[noreturn]] void fail(std::string why);

  std::vector<bringup::ByteEvent> events_;  // host and device only
  drivers::HidDeviceInfo info_;
  bool open_ = false;
  std::shared_ptr<Progress> progress_ = std::make_shared<Progress>();
};

}  // namespace colorlab::test
