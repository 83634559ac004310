#pragma once
// The one error type that crosses module boundaries. Its classes follow ArgyllCMS's two-level
// scheme (a generic class plus device and transport codes) so a campaign can decide to retry,
// recalibrate, reconnect or ask an operator without knowing which instrument failed.
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace colorlab {

enum class ErrorClass {
  timeout,         // no (complete) answer within the deadline
  no_comms,        // link could not be opened or is gone
  coms_fail,       // link open but bytes are wrong: framing, parity, garbled
  protocol_error,  // well-formed but unexpected answer
  device_error,    // the instrument reported an error code
  needs_calibration,
  needs_operator,  // a human must act (power-cycle, place on tile, load chart)
  misread,         // measurement out of range or invalid; a retry may succeed
  unsupported,
  bad_parameter,  // caller asked for something invalid
  hardware_fail,
  bad_data,  // input data (file, spectrum, request) is malformed
  io_error,  // disk, database
  not_found,
  conflict,
  script_error,  // a campaign script failed: syntax, runtime error, budget, forbidden call
  aborted,       // a person or the daemon's shutdown stopped the work on purpose
  internal,
};

std::string_view to_string(ErrorClass c);

struct ErrorInfo {
  ErrorClass cls = ErrorClass::internal;
  std::string message;
  std::string hint;            // what a person should do about it
  std::string device_code;     // e.g. "ER10", "spectrolino:04"
  std::string transport_code;  // e.g. "ETIMEDOUT", "EIO"
  bool retryable = false;
  std::vector<std::string> transcript;  // last bytes exchanged, for diagnosis
};

class Error : public std::runtime_error {
 public:
  explicit Error(ErrorInfo info);
  Error(ErrorClass cls, std::string message, std::string hint = {});

  const ErrorInfo& info() const noexcept { return info_; }
  ErrorClass cls() const noexcept { return info_.cls; }
  const std::string& hint() const noexcept { return info_.hint; }

 private:
  ErrorInfo info_;
};

}  // namespace colorlab
