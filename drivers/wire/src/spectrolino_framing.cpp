#include <bit>
#include <cstdio>

#include "colorlab/wire/spectrolino_protocol.hpp"

namespace colorlab::wire::spectrolino {

namespace {

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

std::string printable(std::string_view s) {
  std::string out;
  for (char c : s) {
    if (c == '\r') {
      out += "\\r";
    } else if (c == '\n') {
      out += "\\n";
    } else if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7E) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02X", static_cast<unsigned char>(c));
      out += buf;
    } else {
      out += c;
    }
  }
  return out;
}

std::string frame(char lead, std::span<const std::uint8_t> body) {
  std::string s;
  s.reserve(body.size() * 2 + 3);
  s += lead;
  s += to_hex(body);
  s += "\r\n";
  return s;
}

Bytes unframe(std::string_view line, char lead, std::string_view kind) {
  std::string_view s = line;
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.remove_suffix(1);
  if (s.empty() || s.front() != lead) {
    throw Error(ErrorClass::coms_fail,
                std::string("Spectrolino ") + std::string(kind) + " does not start with '" + lead + "': '" +
                    printable(line) + "'",
                "line noise, a partial frame or a wrong baud rate");
  }
  return from_hex(s.substr(1), kind);
}

}  // namespace

std::string to_hex(std::span<const std::uint8_t> bytes) {
  static constexpr char digits[] = "0123456789ABCDEF";
  std::string s;
  s.reserve(bytes.size() * 2);
  for (auto b : bytes) {
    s += digits[b >> 4];
    s += digits[b & 0x0F];
  }
  return s;
}

Bytes from_hex(std::string_view hex, std::string_view where) {
  if (hex.size() % 2 != 0) {
    throw Error(ErrorClass::coms_fail,
                "Spectrolino " + std::string(where) + " has an odd number of hex digits (" +
                    std::to_string(hex.size()) + "): '" + printable(hex) + "'",
                "a partial or garbled frame");
  }
  Bytes out;
  out.reserve(hex.size() / 2);
  for (std::size_t i = 0; i < hex.size(); i += 2) {
    int hi = hex_value(hex[i]);
    int lo = hex_value(hex[i + 1]);
    if (hi < 0 || lo < 0) {
      throw Error(ErrorClass::coms_fail,
                  "Spectrolino " + std::string(where) + " has a bad hex digit at offset " + std::to_string(i) +
                      ": '" + printable(hex) + "'",
                  "line noise or a wrong baud rate");
    }
    out.push_back(static_cast<std::uint8_t>(hi << 4 | lo));
  }
  return out;
}

std::string frame_request(std::span<const std::uint8_t> body) { return frame(';', body); }
std::string frame_answer(std::span<const std::uint8_t> body) { return frame(':', body); }
Bytes unframe_request(std::string_view line) { return unframe(line, ';', "request"); }
Bytes unframe_answer(std::string_view line) { return unframe(line, ':', "answer"); }

Writer& Writer::u8(std::uint8_t v) {
  out_.push_back(v);
  return *this;
}
Writer& Writer::u16(std::uint16_t v) {
  out_.push_back(static_cast<std::uint8_t>(v & 0xFF));
  out_.push_back(static_cast<std::uint8_t>(v >> 8));
  return *this;
}
Writer& Writer::u32(std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  return *this;
}
Writer& Writer::f32(float v) { return u32(std::bit_cast<std::uint32_t>(v)); }
Writer& Writer::floats(std::span<const float> v) {
  for (float f : v) f32(f);
  return *this;
}
Writer& Writer::str(std::string_view s, std::size_t len) {
  for (std::size_t i = 0; i < len; ++i) out_.push_back(i < s.size() ? static_cast<std::uint8_t>(s[i]) : 0);
  return *this;
}
Writer& Writer::raw(std::span<const std::uint8_t> b) {
  out_.insert(out_.end(), b.begin(), b.end());
  return *this;
}

Reader::Reader(std::span<const std::uint8_t> bytes, std::string what) : bytes_(bytes), what_(std::move(what)) {}

void Reader::need(std::size_t n, std::string_view field) {
  if (pos_ + n > bytes_.size()) {
    throw Error(ErrorClass::protocol_error,
                what_ + " is too short: field '" + std::string(field) + "' needs " + std::to_string(n) +
                    " byte(s) at offset " + std::to_string(pos_) + " but the body has " +
                    std::to_string(bytes_.size()) + ": " + to_hex(bytes_),
                "a truncated answer; Argyll treats it as 'badly formatted'");
  }
}
std::uint8_t Reader::u8(std::string_view field) {
  need(1, field);
  return bytes_[pos_++];
}
std::uint16_t Reader::u16(std::string_view field) {
  need(2, field);
  std::uint16_t v = static_cast<std::uint16_t>(bytes_[pos_] | bytes_[pos_ + 1] << 8);
  pos_ += 2;
  return v;
}
std::uint32_t Reader::u32(std::string_view field) {
  need(4, field);
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = v << 8 | bytes_[pos_ + static_cast<std::size_t>(i)];
  pos_ += 4;
  return v;
}
float Reader::f32(std::string_view field) { return std::bit_cast<float>(u32(field)); }
Spectrum Reader::spectrum(std::string_view field) {
  need(4 * kSpectrumBands, field);
  Spectrum s{};
  for (auto& v : s) v = f32(field);
  return s;
}
std::string Reader::str(std::size_t len, std::string_view field) {
  need(len, field);
  std::string s;
  for (std::size_t i = 0; i < len; ++i) {
    char c = static_cast<char>(bytes_[pos_ + i]);
    if (c == '\0') break;
    s += c;
  }
  pos_ += len;
  return s;
}
void Reader::literal(std::uint8_t expected, std::string_view field) {
  std::size_t at = pos_;
  std::uint8_t v = u8(field);
  if (v != expected) {
    char buf[96];
    std::snprintf(buf, sizeof buf, " has %02X at offset %zu where the literal '%.*s' must be %02X", v, at,
                  static_cast<int>(field.size()), field.data(), expected);
    throw Error(ErrorClass::protocol_error, what_ + buf + ": " + to_hex(bytes_));
  }
}
void Reader::finish() {
  if (pos_ != bytes_.size()) {
    throw Error(ErrorClass::protocol_error,
                what_ + " has " + std::to_string(bytes_.size() - pos_) + " unexpected trailing byte(s) after offset " +
                    std::to_string(pos_) + ": " + to_hex(bytes_),
                "Argyll treats any unparsed rest as 'badly formatted'");
  }
}

}  // namespace colorlab::wire::spectrolino
