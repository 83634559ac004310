#pragma once
// The LS-100/LS-110 wire format as pure functions, so the driver, the simulator and the tests
// share one definition: ASCII commands ending in CR LF, replies "OKnn,<value>" or "ERxx".
#include <optional>
#include <string>
#include <string_view>

#include "colorlab/core/error.hpp"

namespace colorlab::wire::ls110 {

inline constexpr std::string_view kTerminator = "\r\n";

std::string command_measure();           // "MES\r\n"
std::string command_set_mode(int mode);  // "MDS,04\r\n"; 04 absolute, 08 peak, 09 continuous

struct ErrorCode {
  std::string code;  // "ER10"
  ErrorClass cls;
  std::string meaning;
  std::string hint;
};
// Meaning of a meter error code; unknown codes map to device_error.
ErrorCode lookup_error(std::string_view code);

struct Reply {
  bool ok = false;
  std::string status;           // the two digits after OK
  std::optional<double> value;  // last numeric field, when present
  std::string error_code;       // "ER10" when !ok
};
// Parses one reply line (with or without CR LF). Throws Error{coms_fail} for a garbled line.
Reply parse_reply(std::string_view line);

// "OK00,  245.31\r\n": the shape the meter uses (space-padded value after the comma).
std::string format_ok(double value, int status = 0);
std::string format_error(std::string_view code);

}  // namespace colorlab::wire::ls110
