#include "colorlab/wire/hid_relay_protocol.hpp"

#include "colorlab/core/error.hpp"

namespace colorlab::wire::hidrelay {

std::vector<std::uint8_t> switch_one(int relay, bool on) {
  if (relay < 1 || relay > 8) throw Error(ErrorClass::bad_parameter, "relay number " + std::to_string(relay) + " is outside 1..8");
  std::vector<std::uint8_t> r(kReportDataBytes + 1, 0);
  r[1] = on ? 0xFF : 0xFD;
  r[2] = static_cast<std::uint8_t>(relay);
  return r;
}

std::vector<std::uint8_t> switch_all(bool on) {
  std::vector<std::uint8_t> r(kReportDataBytes + 1, 0);
  r[1] = on ? 0xFE : 0xFC;
  return r;
}

std::vector<std::uint8_t> set_board_id(std::string_view id) {
  if (id.size() != 5) throw Error(ErrorClass::bad_parameter, "relay board id must be 5 characters, got '" + std::string(id) + "'");
  std::vector<std::uint8_t> r(kReportDataBytes + 1, 0);
  r[1] = 0xFA;
  for (std::size_t i = 0; i < 5; ++i) r[2 + i] = static_cast<std::uint8_t>(id[i]);
  return r;
}

BoardState parse_state(const std::vector<std::uint8_t>& data) {
  if (data.size() < kReportDataBytes) {
    throw Error(ErrorClass::protocol_error, "relay state report has " + std::to_string(data.size()) + " bytes, expected 8");
  }
  if (data[5] != 0) throw Error(ErrorClass::protocol_error, "relay state report: board id is not terminated at byte 5");
  BoardState s;
  for (std::size_t i = 0; i < 5; ++i) {
    if (data[i] < 0x20 || data[i] > 0x7E) {
      throw Error(ErrorClass::protocol_error, "relay state report: board id byte " + std::to_string(i) + " is not printable");
    }
    s.id.push_back(static_cast<char>(data[i]));
  }
  s.mask = data[7];
  return s;
}

std::vector<std::uint8_t> encode_state(const BoardState& state) {
  std::vector<std::uint8_t> d(kReportDataBytes, 0);
  for (std::size_t i = 0; i < 5 && i < state.id.size(); ++i) d[i] = static_cast<std::uint8_t>(state.id[i]);
  d[7] = state.mask;
  return d;
}

int relay_count_from_product(std::string_view product) {
  constexpr std::string_view prefix = "USBRelay";
  if (product.size() != prefix.size() + 1 || product.substr(0, prefix.size()) != prefix || product.back() < '1' ||
      product.back() > '8') {
    throw Error(ErrorClass::unsupported, "'" + std::string(product) + "' is not a dcttech USBRelay<N> board",
                "CH551G and ucreatefun boards speak other protocols and cannot report their state");
  }
  return product.back() - '0';
}

}  // namespace colorlab::wire::hidrelay
