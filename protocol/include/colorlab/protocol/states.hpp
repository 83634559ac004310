#pragma once
// Lifecycle of an execution (SiLA's observable command): it is created waiting, runs, and ends
// in exactly one terminal state. On the way it may be `paused` (by a client, until resumed) or
// `suspended` (by the daemon: shutting down, storage refused; resumed by the daemon itself).
// `interrupted` is terminal: an execution a restart found and could not resume (no stored script).
#include <optional>
#include <string_view>

namespace colorlab::protocol {

enum class ExecutionStatus {
  waiting,
  running,
  paused,
  suspended,
  finished_ok,
  finished_error,
  aborted,
  interrupted
};

std::string_view to_string(ExecutionStatus s);
std::optional<ExecutionStatus> execution_status_from_string(std::string_view s);
bool is_terminal(ExecutionStatus s);

}  // namespace colorlab::protocol
