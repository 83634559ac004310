#pragma once
// What every daemon-facing subcommand shares: the API client for the global options, printing an
// answer as text or --json, and campaign parameters given as KEY=VALUE.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/client/api_client.hpp"
#include "commands.hpp"

namespace colorlab::cli {

client::ApiClient make_client(const GlobalOptions& g);
void print(const GlobalOptions& g, const nlohmann::json& j, std::string (*human)(const nlohmann::json&));
// ["readings=5", "lamp=D65"] → {"readings": 5, "lamp": "D65"}: numbers, booleans, arrays and objects
// as JSON, anything else a string. Throws Error{bad_parameter} for an entry without '='.
nlohmann::json parse_params(const std::vector<std::string>& entries);

}  // namespace colorlab::cli
