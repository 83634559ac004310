#pragma once
// A run with every one of its measurements: the run document is small (GET /v1/runs/{id}); its
// measurements come in keyset pages (GET /v1/runs/{id}/measurements), followed to the end here.
#include <string>

#include <nlohmann/json.hpp>

#include "colorlab/client/api_client.hpp"

namespace colorlab::client {

// Every page of the run's measurements, in seq order. `query` adds filters, e.g. "quantity=luminance".
nlohmann::json fetch_measurements(const ApiClient& api, const std::string& run_id, const std::string& query = {});
// The run document with "measurements" filled in from every page.
nlohmann::json fetch_run(const ApiClient& api, const std::string& run_id);

}  // namespace colorlab::client
