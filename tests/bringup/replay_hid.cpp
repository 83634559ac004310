#include "replay_hid.hpp"

#include "colorlab/bringup/transcript_file.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::test {

using bringup::ByteEvent;

ReplayHidTransport::ReplayHidTransport(std::vector<ByteEvent> events, drivers::HidDeviceInfo info) : info_(std::move(info)) {
  for (auto& e : events) {
    if (e.kind == ByteEvent::Kind::host || e.kind == ByteEvent::Kind::device) events_.push_back(std::move(e));
  }
  progress_->size = events_.size();
}

void ReplayHidTransport::fail(std::string why) {
  if (progress_->mismatch.empty()) progress_->mismatch = std::move(why);
  throw Error(ErrorClass::no_comms, "replayed relay board: " + progress_->mismatch);
}

void ReplayHidTransport::expect_host(std::string_view bytes) {
  auto& pos = progress_->position;
  if (pos >= events_.size() || events_[pos].kind != ByteEvent::Kind::host) {
    fail("event " + std::to_string(pos) + ": the driver sent " + bringup::to_hex(bytes) +
         " where the transcript has no host event (did the driver's requests change? then record the transcript again)");
  }
  if (events_[pos].data != bytes) {
    fail("event " + std::to_string(pos) + ": the transcript has the host send " + bringup::to_hex(events_[pos].data) +
         ", the driver sent " + bringup::to_hex(bytes));
  }
  ++pos;
}

void ReplayHidTransport::send_feature_report(const std::vector<std::uint8_t>& report) {
  expect_host({reinterpret_cast<const char*>(report.data()), report.size()});
}

std::vector<std::uint8_t> ReplayHidTransport::get_feature_report(std::uint8_t report_number, std::size_t data_length) {
  const char n = static_cast<char>(report_number);
  expect_host(std::string_view(&n, 1));
  auto& pos = progress_->position;
  if (pos >= events_.size() || events_[pos].kind != ByteEvent::Kind::device) {
    fail("event " + std::to_string(pos) + ": the transcript has no answer to GET_REPORT " + std::to_string(report_number));
  }
  const auto& d = events_[pos++].data;
  std::vector<std::uint8_t> out(d.begin(), d.end());
  if (out.size() > data_length) out.resize(data_length);
  return out;
}

}  // namespace colorlab::test
