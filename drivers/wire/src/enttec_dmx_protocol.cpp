#include "colorlab/wire/enttec_dmx_protocol.hpp"

#include <cstdio>

namespace colorlab::wire::enttec {

namespace {

void expect_label(const Frame& f, std::uint8_t want, const char* what) {
  if (f.label != want) {
    throw Error(ErrorClass::protocol_error, std::string("Enttec ") + what + ": expected label " +
                                                std::to_string(want) + ", got label " + std::to_string(f.label));
  }
}

}  // namespace

std::string to_hex(std::span<const std::uint8_t> bytes) {
  std::string s;
  char buf[4];
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%02X", bytes[i]);
    if (i) s += ' ';
    s += buf;
  }
  return s;
}

Bytes encode_frame(std::uint8_t lbl, std::span<const std::uint8_t> payload) {
  if (payload.size() > kMaxPayload) {
    throw Error(ErrorClass::bad_parameter, "Enttec frame label " + std::to_string(lbl) + " payload of " +
                                               std::to_string(payload.size()) + " bytes exceeds the 600-byte limit");
  }
  Bytes b;
  b.reserve(payload.size() + 5);
  b.push_back(kStart);
  b.push_back(lbl);
  b.push_back(static_cast<std::uint8_t>(payload.size() & 0xFF));
  b.push_back(static_cast<std::uint8_t>(payload.size() >> 8));
  b.insert(b.end(), payload.begin(), payload.end());
  b.push_back(kEnd);
  return b;
}

Frame decode_frame(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < 5) {
    throw Error(ErrorClass::coms_fail, "Enttec frame of " + std::to_string(bytes.size()) +
                                           " bytes is shorter than the 5-byte minimum: " + to_hex(bytes));
  }
  if (bytes[0] != kStart) {
    throw Error(ErrorClass::coms_fail, "Enttec frame does not start with 7E: " + to_hex(bytes.first(5)));
  }
  std::size_t len = bytes[2] | static_cast<std::size_t>(bytes[3]) << 8;
  if (len > kMaxPayload) {
    throw Error(ErrorClass::protocol_error, "Enttec frame label " + std::to_string(bytes[1]) + " declares " +
                                                std::to_string(len) + " bytes, over the 600-byte limit");
  }
  if (bytes.size() != len + 5) {
    throw Error(ErrorClass::coms_fail, "Enttec frame label " + std::to_string(bytes[1]) + " declares " +
                                           std::to_string(len) + " data bytes but the buffer holds " +
                                           std::to_string(bytes.size()) + " bytes in all (expected " +
                                           std::to_string(len + 5) + ")");
  }
  if (bytes.back() != kEnd) {
    throw Error(ErrorClass::coms_fail, "Enttec frame label " + std::to_string(bytes[1]) + " ends with " +
                                           to_hex(bytes.last(1)) + " instead of E7");
  }
  return Frame{bytes[1], Bytes(bytes.begin() + 4, bytes.end() - 1)};
}

std::vector<Frame> FrameParser::feed(std::span<const std::uint8_t> bytes) {
  std::vector<Frame> out;
  for (std::uint8_t b : bytes) {
    if (buf_.empty()) {
      if (b != kStart) {
        ++dropped_bytes_;
        continue;
      }
      buf_.push_back(b);
      continue;
    }
    buf_.push_back(b);
    if (buf_.size() == 4) {
      std::size_t len = buf_[2] | static_cast<std::size_t>(buf_[3]) << 8;
      if (len > kMaxPayload) {
        last_problem_ = "frame label " + std::to_string(buf_[1]) + " declares " + std::to_string(len) +
                        " bytes, over 600";
        ++bad_frames_;
        dropped_bytes_ += buf_.size();
        buf_.clear();
      }
      continue;
    }
    if (buf_.size() < 5) continue;
    std::size_t len = buf_[2] | static_cast<std::size_t>(buf_[3]) << 8;
    if (buf_.size() == len + 5) {
      if (buf_.back() == kEnd) {
        out.push_back(Frame{buf_[1], Bytes(buf_.begin() + 4, buf_.end() - 1)});
      } else {
        last_problem_ = "frame label " + std::to_string(buf_[1]) + " does not end with E7";
        ++bad_frames_;
        dropped_bytes_ += buf_.size();
      }
      buf_.clear();
    }
  }
  return out;
}

Bytes get_parameters_request(std::uint16_t size) {
  std::uint8_t p[] = {static_cast<std::uint8_t>(size & 0xFF), static_cast<std::uint8_t>(size >> 8)};
  return encode_frame(label::GetWidgetParameters, p);
}

std::uint16_t decode_get_parameters_request(const Frame& f) {
  expect_label(f, label::GetWidgetParameters, "get-parameters request");
  if (f.payload.size() != 2) {
    throw Error(ErrorClass::protocol_error, "Enttec get-parameters request has " + std::to_string(f.payload.size()) +
                                                " data bytes; it must have 2 (user-config size)");
  }
  return static_cast<std::uint16_t>(f.payload[0] | f.payload[1] << 8);
}

Bytes get_parameters_reply(const WidgetParameters& p) {
  Bytes d{static_cast<std::uint8_t>(p.firmware & 0xFF), static_cast<std::uint8_t>(p.firmware >> 8), p.break_time,
          p.mab_time, p.output_rate};
  d.insert(d.end(), p.user_config.begin(), p.user_config.end());
  return encode_frame(label::GetWidgetParameters, d);
}

WidgetParameters decode_parameters_reply(const Frame& f) {
  expect_label(f, label::GetWidgetParameters, "parameters reply");
  if (f.payload.size() < 5) {
    throw Error(ErrorClass::protocol_error, "Enttec parameters reply has " + std::to_string(f.payload.size()) +
                                                " data bytes; it needs at least 5");
  }
  WidgetParameters p;
  p.firmware = static_cast<std::uint16_t>(f.payload[0] | f.payload[1] << 8);
  p.break_time = f.payload[2];
  p.mab_time = f.payload[3];
  p.output_rate = f.payload[4];
  p.user_config.assign(f.payload.begin() + 5, f.payload.end());
  return p;
}

Bytes set_parameters_request(const WidgetParameters& p) {
  auto n = static_cast<std::uint16_t>(p.user_config.size());
  Bytes d{static_cast<std::uint8_t>(n & 0xFF), static_cast<std::uint8_t>(n >> 8), p.break_time, p.mab_time,
          p.output_rate};
  d.insert(d.end(), p.user_config.begin(), p.user_config.end());
  return encode_frame(label::SetWidgetParameters, d);
}

WidgetParameters decode_set_parameters_request(const Frame& f) {
  expect_label(f, label::SetWidgetParameters, "set-parameters request");
  if (f.payload.size() < 5) {
    throw Error(ErrorClass::protocol_error, "Enttec set-parameters request has " +
                                                std::to_string(f.payload.size()) + " data bytes; it needs at least 5");
  }
  std::size_t n = f.payload[0] | static_cast<std::size_t>(f.payload[1]) << 8;
  if (f.payload.size() != 5 + n) {
    throw Error(ErrorClass::protocol_error, "Enttec set-parameters request declares " + std::to_string(n) +
                                                " user-config bytes but carries " +
                                                std::to_string(f.payload.size() - 5));
  }
  WidgetParameters p;
  p.break_time = f.payload[2];
  p.mab_time = f.payload[3];
  p.output_rate = f.payload[4];
  p.user_config.assign(f.payload.begin() + 5, f.payload.end());
  if (p.break_time < 9 || p.break_time > 127 || p.mab_time < 1 || p.mab_time > 127 || p.output_rate > 40) {
    throw Error(ErrorClass::bad_parameter,
                "Enttec set-parameters out of range: break " + std::to_string(p.break_time) + " (9..127), MAB " +
                    std::to_string(p.mab_time) + " (1..127), rate " + std::to_string(p.output_rate) + " (0..40)");
  }
  return p;
}

Bytes send_dmx_request(std::span<const std::uint8_t> slots, std::uint8_t start_code) {
  if (slots.size() > kMaxSlots) {
    throw Error(ErrorClass::bad_parameter,
                "DMX packet of " + std::to_string(slots.size()) + " slots exceeds the 512-slot universe");
  }
  Bytes d;
  d.reserve(slots.size() + 1);
  d.push_back(start_code);
  d.insert(d.end(), slots.begin(), slots.end());
  return encode_frame(label::SendDmx, d);
}

DmxPacket decode_send_dmx(const Frame& f) {
  expect_label(f, label::SendDmx, "send-DMX request");
  if (f.payload.empty()) {
    throw Error(ErrorClass::protocol_error, "Enttec send-DMX request has no data; it needs the start code");
  }
  if (f.payload.size() > kMaxSlots + 1) {
    throw Error(ErrorClass::protocol_error, "Enttec send-DMX request carries " +
                                                std::to_string(f.payload.size() - 1) + " slots, over 512");
  }
  return DmxPacket{f.payload[0], Bytes(f.payload.begin() + 1, f.payload.end())};
}

Bytes get_serial_request() { return encode_frame(label::GetSerialNumber, {}); }

Bytes serial_reply(std::uint32_t serial) {
  std::uint8_t d[] = {static_cast<std::uint8_t>(serial), static_cast<std::uint8_t>(serial >> 8),
                      static_cast<std::uint8_t>(serial >> 16), static_cast<std::uint8_t>(serial >> 24)};
  return encode_frame(label::GetSerialNumber, d);
}

std::uint32_t decode_serial_reply(const Frame& f) {
  expect_label(f, label::GetSerialNumber, "serial reply");
  if (f.payload.size() != 4) {
    throw Error(ErrorClass::protocol_error, "Enttec serial reply has " + std::to_string(f.payload.size()) +
                                                " data bytes; it must have 4");
  }
  return static_cast<std::uint32_t>(f.payload[0]) | static_cast<std::uint32_t>(f.payload[1]) << 8 |
         static_cast<std::uint32_t>(f.payload[2]) << 16 | static_cast<std::uint32_t>(f.payload[3]) << 24;
}

std::uint32_t bcd_serial(std::uint32_t decimal) {
  std::uint32_t out = 0;
  for (int shift = 0; shift < 32 && decimal; shift += 4) {
    out |= (decimal % 10) << shift;
    decimal /= 10;
  }
  return out;
}

}  // namespace colorlab::wire::enttec
