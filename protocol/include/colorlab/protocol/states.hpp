#pragma once
// Lifecycle of an execution (SiLA's observable command): it is created waiting, runs, and ends
// in exactly one terminal state. `interrupted` is what a restart finds for one the process lost.
#include <optional>
#include <string_view>

namespace colorlab::protocol {

enum class ExecutionStatus { waiting, running, finished_ok, finished_error, aborted, interrupted };

std::string_view to_string(ExecutionStatus s);
std::optional<ExecutionStatus> execution_status_from_string(std::string_view s);
bool is_terminal(ExecutionStatus s);

}  // namespace colorlab::protocol
