#include "colorlab/wire/ls110_protocol.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace colorlab::wire::ls110 {

std::string command_measure() { return "MES\r\n"; }

std::string command_set_mode(int mode) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "MDS,%02d\r\n", mode);
  return buf;
}

ErrorCode lookup_error(std::string_view code) {
  std::string c(code);
  if (c == "ER00") return {c, ErrorClass::protocol_error, "unknown or invalid command", "a driver bug: report the transcript"};
  if (c == "ER01") return {c, ErrorClass::bad_parameter, "setting error", "check the requested measuring mode"};
  if (c == "ER10")
    return {c, ErrorClass::misread, "measuring range over",
            "the spot is brighter than the meter's range: dim the lamp or check the aim"};
  if (c == "ER11") return {c, ErrorClass::device_error, "memory value error", "clear the meter's memory (CLE)"};
  if (c == "ER19") return {c, ErrorClass::misread, "display range over", "the value exceeds the display range"};
  if (c == "ER20") return {c, ErrorClass::hardware_fail, "EEPROM error", "the meter needs repair"};
  if (c == "ER30") return {c, ErrorClass::needs_operator, "battery exhausted", "replace the meter's battery"};
  return {c, ErrorClass::device_error, "unknown meter error", "see the LS-110 manual"};
}

namespace {

std::string_view trim_line(std::string_view s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

}  // namespace

Reply parse_reply(std::string_view raw) {
  std::string_view line = trim_line(raw);
  Reply r;
  if (line.size() >= 4 && line.substr(0, 2) == "ER" && std::isdigit(static_cast<unsigned char>(line[2])) &&
      std::isdigit(static_cast<unsigned char>(line[3]))) {
    r.ok = false;
    r.error_code = std::string(line.substr(0, 4));
    return r;
  }
  if (line.size() < 2 || line.substr(0, 2) != "OK") {
    throw Error(ErrorClass::coms_fail, "LS-110 reply is neither OK nor ER: '" + std::string(line) + "'",
                "line noise or a wrong baud rate/framing (the meter uses 4800 7E2)");
  }
  r.ok = true;
  std::string_view rest = line.substr(2);
  std::size_t digits = 0;
  while (digits < rest.size() && digits < 2 && std::isdigit(static_cast<unsigned char>(rest[digits]))) ++digits;
  r.status = std::string(rest.substr(0, digits));
  rest.remove_prefix(digits);
  auto comma = rest.rfind(',');
  if (comma == std::string_view::npos) {
    if (rest.find_first_not_of(' ') != std::string_view::npos) {
      throw Error(ErrorClass::coms_fail, "LS-110 reply has trailing garbage: '" + std::string(line) + "'");
    }
    return r;  // a plain acknowledgement, e.g. to MDS
  }
  std::string_view field = rest.substr(comma + 1);
  while (!field.empty() && field.front() == ' ') field.remove_prefix(1);
  while (!field.empty() && field.back() == ' ') field.remove_suffix(1);
  double v = 0;
  auto [ptr, ec] = std::from_chars(field.data(), field.data() + field.size(), v);
  // from_chars also reads "inf" and "nan", which the meter never sends: garbled, not a reading.
  if (ec != std::errc() || ptr != field.data() + field.size() || !std::isfinite(v)) {
    throw Error(ErrorClass::coms_fail, "LS-110 value is not a number: '" + std::string(line) + "'",
                "line noise or a partial frame; the measurement is retried");
  }
  r.value = v;
  return r;
}

std::string format_ok(double value, int status) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "OK%02d,%9.2f\r\n", status, value);
  return buf;
}

std::string format_error(std::string_view code) { return std::string(code) + "\r\n"; }

}  // namespace colorlab::wire::ls110
