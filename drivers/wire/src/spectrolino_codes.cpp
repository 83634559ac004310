#include <cstdio>

#include "colorlab/wire/spectrolino_protocol.hpp"

namespace colorlab::wire::spectrolino {

namespace {

struct Entry {
  std::uint8_t code;
  std::string_view meaning;
  ArgyllClass argyll;
  ErrorClass cls;
};

constexpr Entry kExecErrors[] = {
    {0x00, "no error", ArgyllClass::ok, ErrorClass::internal},
    {0x01, "memory failure", ArgyllClass::hardware, ErrorClass::hardware_fail},
    {0x02, "power failure", ArgyllClass::hardware, ErrorClass::hardware_fail},
    {0x04, "lamp failure", ArgyllClass::hardware, ErrorClass::hardware_fail},
    {0x05, "hardware failure", ArgyllClass::hardware, ErrorClass::hardware_fail},
    {0x06, "filter wheel out of position", ArgyllClass::hardware, ErrorClass::hardware_fail},
    {0x07, "data transmission timeout", ArgyllClass::comms_fail, ErrorClass::coms_fail},
    {0x08, "drive defect", ArgyllClass::hardware, ErrorClass::hardware_fail},
    {0x09, "measuring disabled", ArgyllClass::misread, ErrorClass::misread},
    {0x0A, "bad input during density calibration", ArgyllClass::other, ErrorClass::device_error},
    {0x0D, "EPROM defective", ArgyllClass::hardware, ErrorClass::hardware_fail},
    {0x0E, "too much light or wrong white calibration", ArgyllClass::misread, ErrorClass::misread},
    {0x10, "memory checksum error", ArgyllClass::hardware, ErrorClass::hardware_fail},
    {0x11, "memory full", ArgyllClass::hardware, ErrorClass::hardware_fail},
    {0x13, "white measurement OK", ArgyllClass::notify, ErrorClass::internal},
    {0x15, "not ready, wait", ArgyllClass::other, ErrorClass::device_error},
    {0x32, "white measurement warning", ArgyllClass::warning, ErrorClass::needs_calibration},
    {0x33, "reset done", ArgyllClass::notify, ErrorClass::internal},
    {0x34, "emission calibration OK", ArgyllClass::notify, ErrorClass::internal},
    {0x35, "only valid for emission", ArgyllClass::other, ErrorClass::bad_parameter},
    {0x36, "wrong checksum", ArgyllClass::hardware, ErrorClass::hardware_fail},
    {0x37, "no valid measurement (e.g. no white calibration yet)", ArgyllClass::other, ErrorClass::needs_calibration},
    {0x38, "backup error", ArgyllClass::hardware, ErrorClass::hardware_fail},
    {0x3C, "program ROM error", ArgyllClass::hardware, ErrorClass::hardware_fail},
};

constexpr Entry kScanErrors[] = {
    {0x00, "no error", ArgyllClass::ok, ErrorClass::internal},
    {0x01, "device is offline", ArgyllClass::other, ErrorClass::needs_operator},
    {0x02, "parameter out of range", ArgyllClass::other, ErrorClass::bad_parameter},
    {0x03, "flash-EPROM write error", ArgyllClass::hardware, ErrorClass::hardware_fail},
    {0x04, "no access to internal function", ArgyllClass::unsupported, ErrorClass::unsupported},
    {0x05, "unknown command", ArgyllClass::unsupported, ErrorClass::unsupported},
    {0x06, "Spectrolino not found", ArgyllClass::other, ErrorClass::hardware_fail},
    {0x07, "measurement error", ArgyllClass::misread, ErrorClass::misread},
    {0x08, "transmission command but no transmission table", ArgyllClass::other, ErrorClass::unsupported},
    {0x09, "transmission command while in reflection mode", ArgyllClass::other, ErrorClass::protocol_error},
    {0x0A, "reflection command while in transmission mode", ArgyllClass::other, ErrorClass::protocol_error},
};

constexpr Entry kComErrors[] = {
    {0x00, "none", ArgyllClass::ok, ErrorClass::internal},
    {0x01, "stop but no start character", ArgyllClass::comms_fail, ErrorClass::coms_fail},
    {0x02, "illegal character in record", ArgyllClass::comms_fail, ErrorClass::coms_fail},
    {0x03, "wrong record length", ArgyllClass::comms_fail, ErrorClass::coms_fail},
    {0x04, "illegal record type (unknown message number)", ArgyllClass::comms_fail, ErrorClass::protocol_error},
    {0x06, "no tag field", ArgyllClass::comms_fail, ErrorClass::coms_fail},
    {0x07, "conversion error", ArgyllClass::comms_fail, ErrorClass::coms_fail},
    {0x08, "invalid for emission instrument", ArgyllClass::comms_fail, ErrorClass::unsupported},
    {0x10, "no access (user identification failed)", ArgyllClass::comms_fail, ErrorClass::unsupported},
};

// Kept as laid out by hand: two bits a row.
// clang-format off
constexpr RemoteBit kRemoteBits[] = {
    {0x0001, "no valid density standard"}, {0x0002, "no valid white standard"},
    {0x0004, "no valid illuminant"},       {0x0008, "no valid observer"},
    {0x0010, "no valid max lambda"},       {0x0020, "no valid spectrum"},
    {0x0040, "no valid colour system or index"}, {0x0080, "no valid character"},
    {0x0100, "slope out of range"},        {0x0200, "density out of range"},
    {0x0400, "reflectance out of range"},  {0x0800, "colour value 1 out of range"},
    {0x1000, "colour value 2 out of range"}, {0x2000, "colour value 3 out of range"},
    {0x4000, "not an SR or boolean"},      {0x8000, "no valid value or reference"},
};
// clang-format on

template <std::size_t N>
CodeInfo lookup(const Entry (&table)[N], std::uint8_t code) {
  for (const auto& e : table) {
    if (e.code == code) return {code, e.meaning, e.argyll, e.cls, true};
  }
  return {code, "unknown code", ArgyllClass::other, ErrorClass::device_error, false};
}

std::string hex2(std::uint8_t v) {
  char buf[4];
  std::snprintf(buf, sizeof buf, "%02X", v);
  return buf;
}

std::string hint_for(ErrorClass cls) {
  switch (cls) {
    case ErrorClass::hardware_fail: return "the instrument reports a hardware fault: check lamp, filter and cabling";
    case ErrorClass::misread: return "retry the reading; check the head is on the sample";
    case ErrorClass::needs_calibration: return "run a white calibration on the tile";
    case ErrorClass::needs_operator: return "put the table online (D0 10) or ask the operator";
    case ErrorClass::coms_fail: return "check the serial link (speed, handshake)";
    case ErrorClass::unsupported: return "the instrument does not support this command";
    default: return "see instrument-protocols.md §1.8";
  }
}

}  // namespace

std::string_view to_string(ArgyllClass c) {
  switch (c) {
    case ArgyllClass::ok: return "ok";
    case ArgyllClass::notify: return "notify";
    case ArgyllClass::warning: return "warning";
    case ArgyllClass::comms_fail: return "comms_fail";
    case ArgyllClass::misread: return "misread";
    case ArgyllClass::hardware: return "hardware";
    case ArgyllClass::unsupported: return "unsupported";
    case ArgyllClass::other: return "other";
  }
  return "other";
}

CodeInfo describe_exec_error(std::uint8_t code) { return lookup(kExecErrors, code); }
CodeInfo describe_scan_error(std::uint8_t code) { return lookup(kScanErrors, code); }
CodeInfo describe_com_error(std::uint8_t code) { return lookup(kComErrors, code); }

std::vector<RemoteBit> describe_remote_errors(std::uint16_t set) {
  std::vector<RemoteBit> out;
  for (const auto& b : kRemoteBits) {
    if (set & b.bit) out.push_back(b);
  }
  return out;
}

void throw_on_exec_error(std::uint8_t code, std::string_view op_name, std::initializer_list<std::uint8_t> success) {
  if (code == exec_err::NoError) return;
  for (auto s : success) {
    if (s == code) return;
  }
  CodeInfo info = describe_exec_error(code);
  ErrorClass cls = info.cls == ErrorClass::internal ? ErrorClass::protocol_error : info.cls;
  ErrorInfo e;
  e.cls = cls;
  e.message = std::string(op_name) + ": Spectrolino error " + hex2(code) + " (" + std::string(info.meaning) + ")";
  e.hint = hint_for(cls);
  e.device_code = "spectrolino:" + hex2(code);
  e.retryable = cls == ErrorClass::misread || cls == ErrorClass::coms_fail || code == exec_err::NotReady;
  throw Error(std::move(e));
}

void throw_on_scan_error(std::uint8_t code, std::string_view op_name) {
  if (code == scan_err::NoError) return;
  CodeInfo info = describe_scan_error(code);
  ErrorInfo e;
  e.cls = info.cls;
  e.message = std::string(op_name) + ": SpectroScan error " + hex2(code) + " (" + std::string(info.meaning) + ")";
  e.hint = hint_for(info.cls);
  e.device_code = "spectroscan:" + hex2(code);
  e.retryable = info.cls == ErrorClass::misread;
  throw Error(std::move(e));
}

void throw_on_remote_error(std::uint16_t set, std::string_view op_name) {
  if (set == 0) return;
  std::string msg = std::string(op_name) + ": Spectrolino remote error set ";
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04X", set);
  msg += buf;
  msg += " (";
  bool first = true;
  bool range = false;
  for (const auto& b : describe_remote_errors(set)) {
    if (!first) msg += ", ";
    msg += b.meaning;
    first = false;
    if (b.bit >= 0x0100 && b.bit <= 0x2000) range = true;
  }
  msg += ")";
  ErrorInfo e;
  e.cls = range ? ErrorClass::misread : ErrorClass::bad_parameter;
  e.message = std::move(msg);
  e.hint = range ? "the value is out of the instrument's range; check the sample" : "check the parameters sent";
  e.device_code = std::string("spectrolino-remote:") + buf;
  e.retryable = range;
  throw Error(std::move(e));
}

std::optional<int> ctt_baud(std::uint8_t code) {
  static constexpr int speeds[] = {110, 150, 300, 600, 1200, 2400, 4800, 9600, 19200};
  if (code >= ctt::Baud110 && code <= ctt::Baud19200) return speeds[code - ctt::Baud110];
  if (code == ctt::Baud28800) return 28800;
  if (code == ctt::Baud57600) return 57600;
  return std::nullopt;
}

std::optional<std::uint8_t> baud_ctt(int baud) {
  for (int c = ctt::Baud110; c <= ctt::Baud19200; ++c) {
    if (ctt_baud(static_cast<std::uint8_t>(c)) == baud) return static_cast<std::uint8_t>(c);
  }
  if (baud == 28800) return ctt::Baud28800;
  if (baud == 57600) return ctt::Baud57600;
  return std::nullopt;
}

std::optional<int> scan_bt_baud(std::uint8_t bt) {
  static constexpr int speeds[] = {110, 150, 300, 600, 1200, 2400, 4800, 9600, 19200, 28800, 57600};
  if (bt < std::size(speeds)) return speeds[bt];
  return std::nullopt;
}

std::optional<std::uint8_t> baud_scan_bt(int baud) {
  for (std::uint8_t bt = 0; bt <= 0x0A; ++bt) {
    if (scan_bt_baud(bt) == baud) return bt;
  }
  return std::nullopt;
}

bool valid_illuminant(std::uint8_t v) {
  return v == 0x00 || v == 0x01 || v == 0x02 || v == 0x03 || v == 0x08 || v == 0x10 || (v >= 0x18 && v <= 0x23);
}

std::string_view illuminant_name(Illuminant il) {
  static constexpr std::string_view fl[] = {"F1", "F2", "F3", "F4", "F5", "F6",
                                            "F7", "F8", "F9", "F10", "F11", "F12"};
  auto v = static_cast<std::uint8_t>(il);
  switch (il) {
    case Illuminant::A: return "A";
    case Illuminant::C: return "C";
    case Illuminant::D65: return "D65";
    case Illuminant::D50: return "D50";
    case Illuminant::User: return "user";
    case Illuminant::Dxx: return "Dxx";
    default:
      if (v >= 0x18 && v <= 0x23) return fl[v - 0x18];
      return "unknown";
  }
}

}  // namespace colorlab::wire::spectrolino
