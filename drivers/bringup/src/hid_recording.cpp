#include "colorlab/bringup/hid_recording.hpp"

#include <string>

namespace colorlab::bringup {

namespace {
std::string_view as_chars(const std::vector<std::uint8_t>& v) {
  return {reinterpret_cast<const char*>(v.data()), v.size()};
}
}  // namespace

void RecordingHidTransport::send_feature_report(const std::vector<std::uint8_t>& report) {
  recording_.mark("SET_REPORT feature, " + std::to_string(report.size()) + " bytes");
  recording_.host(as_chars(report));
  inner_->send_feature_report(report);
}

std::vector<std::uint8_t> RecordingHidTransport::get_feature_report(std::uint8_t report_number, std::size_t data_length) {
  recording_.mark("GET_REPORT feature " + std::to_string(report_number) + ", " + std::to_string(data_length) + " bytes");
  const char n = static_cast<char>(report_number);
  recording_.host(std::string_view(&n, 1));
  auto data = inner_->get_feature_report(report_number, data_length);
  recording_.device(as_chars(data));
  return data;
}

}  // namespace colorlab::bringup
