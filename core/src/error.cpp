#include "colorlab/core/error.hpp"

namespace colorlab {

std::string_view to_string(ErrorClass c) {
  switch (c) {
    case ErrorClass::timeout: return "timeout";
    case ErrorClass::no_comms: return "no_comms";
    case ErrorClass::coms_fail: return "coms_fail";
    case ErrorClass::protocol_error: return "protocol_error";
    case ErrorClass::device_error: return "device_error";
    case ErrorClass::needs_calibration: return "needs_calibration";
    case ErrorClass::needs_operator: return "needs_operator";
    case ErrorClass::misread: return "misread";
    case ErrorClass::unsupported: return "unsupported";
    case ErrorClass::bad_parameter: return "bad_parameter";
    case ErrorClass::hardware_fail: return "hardware_fail";
    case ErrorClass::bad_data: return "bad_data";
    case ErrorClass::io_error: return "io_error";
    case ErrorClass::not_found: return "not_found";
    case ErrorClass::conflict: return "conflict";
    case ErrorClass::script_error: return "script_error";
    case ErrorClass::aborted: return "aborted";
    case ErrorClass::internal: return "internal";
  }
  return "internal";
}

static std::string compose(const ErrorInfo& i) {
  std::string s{to_string(i.cls)};
  s += ": ";
  s += i.message;
  if (!i.device_code.empty()) s += " [device " + i.device_code + "]";
  if (!i.transport_code.empty()) s += " [transport " + i.transport_code + "]";
  return s;
}

Error::Error(ErrorInfo info) : std::runtime_error(compose(info)), info_(std::move(info)) {}

Error::Error(ErrorClass cls, std::string message, std::string hint)
    : Error(ErrorInfo{cls, std::move(message), std::move(hint), {}, {}, false, {}}) {}

}  // namespace colorlab
