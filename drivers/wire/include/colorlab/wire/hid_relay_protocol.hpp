#pragma once
// The dcttech "USBRelay<N>" board's feature reports as pure functions (instrument-protocols §3b),
// shared by the driver and the scripted board in sim/relay.
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace colorlab::wire::hidrelay {

inline constexpr std::size_t kReportDataBytes = 8;

std::vector<std::uint8_t> switch_one(int relay, bool on);     // 00 FF|FD n 00…  (9 bytes)
std::vector<std::uint8_t> switch_all(bool on);                // 00 FE|FC 00…
std::vector<std::uint8_t> set_board_id(std::string_view id);  // 00 FA c1..c5 00 00

struct BoardState {
  std::string id;         // 5 ASCII characters
  std::uint8_t mask = 0;  // bit0 = relay 1, set = on
};
// `data` is the 8 data bytes of GET_REPORT(feature). Throws Error{protocol_error} if malformed.
BoardState parse_state(const std::vector<std::uint8_t>& data);
std::vector<std::uint8_t> encode_state(const BoardState& state);

// "USBRelay2" → 2; throws Error{unsupported} for other products.
int relay_count_from_product(std::string_view product);

}  // namespace colorlab::wire::hidrelay
