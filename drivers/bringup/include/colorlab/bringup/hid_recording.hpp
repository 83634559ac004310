#pragma once
// A HidTransport that records every feature report it passes on into a bring-up Recording, so a
// relay board's bytes land in the same transcript format as the serial instruments' (docs/bring-up.md,
// "Transcript files"). A GET_REPORT is recorded as a mark, a "host" event holding the report number
// asked for, then a "device" event with the data bytes the board answered; a SET_REPORT as a mark and
// a "host" event holding the whole report (report number first).
#include <memory>

#include "colorlab/bringup/recording.hpp"
#include "colorlab/wire/hid_transport.hpp"

namespace colorlab::bringup {

class RecordingHidTransport : public drivers::HidTransport {
 public:
  // `recording` must outlive this transport.
  RecordingHidTransport(std::unique_ptr<drivers::HidTransport> inner, Recording& recording)
      : inner_(std::move(inner)), recording_(recording) {}

  void open() override { inner_->open(); }
  void close() override { inner_->close(); }
  bool is_open() const override { return inner_->is_open(); }
  drivers::HidDeviceInfo info() const override { return inner_->info(); }
  void send_feature_report(const std::vector<std::uint8_t>& report) override;
  std::vector<std::uint8_t> get_feature_report(std::uint8_t report_number, std::size_t data_length) override;

 private:
  std::unique_ptr<drivers::HidTransport> inner_;
  Recording& recording_;
};

}  // namespace colorlab::bringup
