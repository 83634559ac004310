#pragma once
// A campaign script as the daemon knows it: its text, its SHA-256 (a run stores both, so a resume
// uses exactly the text it started with), and the declaration its top level returns — name,
// description, the instrument roles it needs, its parameters with type, unit, default and limits.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/campaigns/lua_sandbox.hpp"

namespace colorlab::campaigns {

// The roles a script may ask for in `needs`, each met by the first instrument with the capability.
inline constexpr const char* kRoles[] = {"luminance_meter", "spectrophotometer", "table", "lamps", "dimmer", "camera"};

struct CampaignScript {
  std::string name;            // the file's stem; the API's campaign name
  std::filesystem::path path;  // empty for a script read back from a run
  std::string origin;          // "shipped", "lab" or "stored"
  std::string source;
  std::string sha256;
  std::string description;
  std::vector<std::string> needs;
  nlohmann::json parameters = nlohmann::json::object();  // name → {type, default, minimum, maximum, unit, description, ...}
  ScriptLimits limits;

  // GET /v1/campaigns's view.
  nlohmann::json to_json() const;
  // Every declared parameter, defaults filled in; throws Error{bad_parameter} naming the first
  // offending parameter (unknown, wrong type, out of limits) before anything moves.
  nlohmann::json validate(const nlohmann::json& params) const;
};

// Runs the script's top level in a sandbox and reads its declaration. Throws Error{script_error}
// naming the file and line for a script that does not compile or declares nonsense.
CampaignScript parse_campaign_script(const std::string& name, const std::string& source);

std::string sha256_hex(const std::string& data);

}  // namespace colorlab::campaigns
