#pragma once
// Following an execution live by the daemon's event stream (no polling): a progress bar with ETA on a
// terminal, a line per change otherwise, the operator's requests as they are posted.
#include <nlohmann/json.hpp>

#include "colorlab/client/api_client.hpp"
#include "commands.hpp"

namespace colorlab::cli {

// Returns the execution as it ended. `quiet`: no progress output (--id-only, --json).
nlohmann::json follow_execution(const client::ApiClient& api, nlohmann::json execution, bool quiet);

}  // namespace colorlab::cli
