#pragma once
// What every daemon-facing subcommand shares: the API client for the global options, printing an
// answer as text or --json, and campaign parameters given as KEY=VALUE.
#include <filesystem>
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
// A GET whose body is a file (an export, a blob): the bytes as sent; a refusal throws ApiError with the
// server's problem (exit code 2).
client::RawResponse fetch_bytes(const GlobalOptions& g, const std::string& target);
// Writes bytes to a file; Error{io_error} saying which file when it cannot.
void write_bytes(const std::filesystem::path& path, const std::string& bytes);
// A run id or blob hash checked, not escaped: anything but hex digits and '-' would name another route.
void check_id(const std::string& id, const std::string& what, const std::string& hint);

}  // namespace colorlab::cli
