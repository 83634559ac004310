#include "colorlab/drivers/socket_hid_transport.hpp"

#include <nlohmann/json.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/unix_line_client.hpp"

namespace colorlab::drivers {

using nlohmann::json;

namespace {

std::string to_hex(const std::vector<std::uint8_t>& bytes) {
  static constexpr char digits[] = "0123456789abcdef";
  std::string out;
  for (auto b : bytes) {
    out.push_back(digits[b >> 4]);
    out.push_back(digits[b & 0xF]);
  }
  return out;
}

std::vector<std::uint8_t> from_hex(const std::string& hex) {
  auto nibble = [&](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    throw Error(ErrorClass::protocol_error, "HID socket: report data '" + hex + "' is not hex");
  };
  if (hex.size() % 2) throw Error(ErrorClass::protocol_error, "HID socket: report data '" + hex + "' has an odd length");
  std::vector<std::uint8_t> out;
  for (std::size_t i = 0; i < hex.size(); i += 2) out.push_back(static_cast<std::uint8_t>(nibble(hex[i]) * 16 + nibble(hex[i + 1])));
  return out;
}

}  // namespace

SocketHidTransport::SocketHidTransport(std::string socket_path, std::chrono::milliseconds reply_timeout)
    : socket_path_(std::move(socket_path)),
      reply_timeout_(reply_timeout),
      link_(std::make_unique<UnixLineClient>("HID relay socket " + socket_path_)) {
  info_.path = "unix:" + socket_path_;
}

SocketHidTransport::~SocketHidTransport() = default;

bool SocketHidTransport::is_open() const { return link_->is_open(); }

json SocketHidTransport::call(const json& request) {
  const auto deadline = UnixLineClient::Clock::now() + reply_timeout_;
  try {
    link_->send_line(request.dump(), deadline);
    const std::string line = link_->read_line(deadline);
    json answer = json::parse(line, nullptr, false);
    if (answer.is_discarded() || !answer.is_object() || !answer.contains("ok")) {
      throw Error(ErrorClass::protocol_error, "HID relay socket " + socket_path_ + ": not a protocol answer: " + line,
                  "driver and simulator disagree about the HID socket protocol (docs/simulator.md)");
    }
    if (answer["ok"] == true) return answer;
    // value() throws json's type_error for a field of another type: read only what is text.
    auto text = [&](const char* key, const std::string& otherwise) {
      return answer.contains(key) && answer[key].is_string() ? answer[key].get<std::string>() : otherwise;
    };
    const std::string code = text("error", "?");
    const std::string message = "relay board " + info_.path + ": " + text("message", code);
    if (code == "no_device") throw Error(ErrorClass::no_comms, message, "reconnect the USB cable");
    throw Error(ErrorClass::protocol_error, message, "driver and simulator disagree about the HID socket protocol");
  } catch (const Error&) {
    // After any failure the stream may be out of step (a late answer, half a line): HidRelay's
    // reconnect opens afresh, as it reopens a real board's hidraw node.
    link_->close();
    throw;
  }
}

void SocketHidTransport::open() {
  link_->connect(socket_path_);
  const json a = call({{"op", "open"}});
  try {
    // json's get<uint16_t>() of 1e300 is undefined behaviour and of 70000 a silent wrap: USB ids only.
    auto usb_id = [&](const char* key) {
      const json& v = a.at(key);
      if (!v.is_number_unsigned() || v.get<std::uint64_t>() > 0xFFFF) {
        link_->close();
        throw Error(ErrorClass::protocol_error, "HID relay socket " + socket_path_ + ": " + key + " " + v.dump() + " is not a USB id");
      }
      return static_cast<std::uint16_t>(v.get<std::uint64_t>());
    };
    info_.vendor_id = usb_id("vendor_id");
    info_.product_id = usb_id("product_id");
    info_.manufacturer = a.at("manufacturer").get<std::string>();
    info_.product = a.at("product").get<std::string>();
    info_.serial = a.value("serial", std::string());
  } catch (const json::exception& e) {
    link_->close();
    throw Error(ErrorClass::protocol_error, "HID relay socket " + socket_path_ + ": open answer lacks a field: " + e.what());
  }
}

void SocketHidTransport::close() { link_->close(); }

void SocketHidTransport::send_feature_report(const std::vector<std::uint8_t>& report) {
  if (!link_->is_open()) throw Error(ErrorClass::no_comms, "relay board " + info_.path + " is not open");
  call({{"op", "set_feature"}, {"report", to_hex(report)}});
}

std::vector<std::uint8_t> SocketHidTransport::get_feature_report(std::uint8_t report_number, std::size_t data_length) {
  if (!link_->is_open()) throw Error(ErrorClass::no_comms, "relay board " + info_.path + " is not open");
  const json a = call({{"op", "get_feature"}, {"report", report_number}, {"length", data_length}});
  if (!a.contains("data") || !a["data"].is_string()) {
    throw Error(ErrorClass::protocol_error, "HID relay socket " + socket_path_ + ": get_feature answer without data");
  }
  auto data = from_hex(a["data"].get<std::string>());
  data.resize(data_length, 0);  // as hidapi: the caller asked for exactly this many data bytes
  return data;
}

}  // namespace colorlab::drivers
