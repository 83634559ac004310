#pragma once
// Sequences from the command line (colorlab run NAME / colorlab queue add NAME where NAME is a
// sequence of the daemon's catalogue): every step queued at once as one group, then followed by the
// event stream, step by step.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/client/api_client.hpp"

namespace colorlab::cli {

// True if GET /v1/campaigns lists `name` with kind "sequence".
bool names_sequence(const client::ApiClient& api, const std::string& name);
// POST /v1/queue {"sequence", "small", "overrides", "on_failure", "start"}; `params` are STEP.KEY=VALUE;
// `start`: the daemon starts the queue in the same request.
nlohmann::json queue_sequence(const client::ApiClient& api, const std::string& name,
                              const std::vector<std::string>& params, bool small, const std::string& on_failure,
                              const std::string& idempotency_key, bool start);
// Follows the group's items to the group's end (each running item's execution live, as colorlab run
// does); returns the group as it ended (state done or failed).
nlohmann::json follow_group(const client::ApiClient& api, nlohmann::json group, bool quiet);

}  // namespace colorlab::cli
