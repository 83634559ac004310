#include "colorlab/protocol/states.hpp"

namespace colorlab::protocol {

std::string_view to_string(ExecutionStatus s) {
  switch (s) {
    case ExecutionStatus::waiting: return "waiting";
    case ExecutionStatus::running: return "running";
    case ExecutionStatus::paused: return "paused";
    case ExecutionStatus::suspended: return "suspended";
    case ExecutionStatus::finished_ok: return "finished_ok";
    case ExecutionStatus::finished_error: return "finished_error";
    case ExecutionStatus::aborted: return "aborted";
    case ExecutionStatus::interrupted: return "interrupted";
  }
  return "finished_error";
}

std::optional<ExecutionStatus> execution_status_from_string(std::string_view s) {
  for (auto st : {ExecutionStatus::waiting, ExecutionStatus::running, ExecutionStatus::paused,
                  ExecutionStatus::suspended, ExecutionStatus::finished_ok,
                  ExecutionStatus::finished_error, ExecutionStatus::aborted, ExecutionStatus::interrupted}) {
    if (to_string(st) == s) return st;
  }
  return std::nullopt;
}

bool is_terminal(ExecutionStatus s) {
  return s == ExecutionStatus::finished_ok || s == ExecutionStatus::finished_error || s == ExecutionStatus::aborted ||
         s == ExecutionStatus::interrupted;
}

}  // namespace colorlab::protocol
