#include "colorlab/campaigns/script.hpp"

#include <openssl/evp.h>

#include <algorithm>
#include <cmath>

#include <lua5.4/lua.hpp>

#include "colorlab/campaigns/lab_api.hpp"
#include "colorlab/campaigns/lua_value.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::campaigns {

using nlohmann::json;

std::string sha256_hex(const std::string& data) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  if (EVP_Digest(data.data(), data.size(), digest, &length, EVP_sha256(), nullptr) != 1) {
    throw Error(ErrorClass::internal, "SHA-256 failed");
  }
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  for (unsigned i = 0; i < length; ++i) {
    out += kHex[digest[i] >> 4];
    out += kHex[digest[i] & 15];
  }
  return out;
}

namespace {

const std::vector<std::string> kTypes = {"integer", "number", "string", "boolean", "array"};

[[noreturn]] void bad_declaration(const std::string& script, const std::string& what) {
  throw Error(ErrorClass::script_error, script + ".lua: " + what,
              "a campaign script returns {description = ..., needs = {...}, parameters = {...}, run = function(p) ... end}");
}

void check_parameter_spec(const std::string& script, const std::string& name, json& spec) {
  if (!spec.is_object()) bad_declaration(script, "parameter '" + name + "' must be a table");
  // json's value() throws its own type_error for a field of another type: each is checked first.
  for (const char* key : {"type", "items", "description", "unit"}) {
    if (spec.contains(key) && !spec[key].is_string()) bad_declaration(script, "parameter '" + name + "'." + key + " must be a string");
  }
  std::string type = spec.value("type", std::string());
  if (std::find(kTypes.begin(), kTypes.end(), type) == kTypes.end()) {
    bad_declaration(script, "parameter '" + name + "' has type '" + type + "'; use integer, number, string, boolean or array");
  }
  for (const char* key : {"min", "max", "min_items", "max_items"}) {
    if (spec.contains(key) && !spec[key].is_number()) bad_declaration(script, "parameter '" + name + "'." + key + " must be a number");
  }
  if (spec.contains("values") && !spec["values"].is_array()) bad_declaration(script, "parameter '" + name + "'.values must be a list");
  if (type == "array") {
    std::string items = spec.value("items", std::string("number"));
    if (items != "integer" && items != "number" && items != "string") {
      bad_declaration(script, "parameter '" + name + "'.items must be integer, number or string");
    }
    spec["items"] = items;
  }
  if (!spec.contains("description")) spec["description"] = "";
  if (!spec.contains("unit")) spec["unit"] = "";
  if (!spec.contains("default")) spec["default"] = nullptr;
  if (type == "array" && spec["default"].is_object() && spec["default"].empty()) spec["default"] = json::array();
  if (!spec["default"].is_null()) {
    // A script whose own default breaks its own limits would fail every run: refuse it now.
    CampaignScript probe;
    probe.name = script;
    probe.parameters = json{{name, spec}};
    try {
      probe.validate(json{{name, spec["default"]}});
    } catch (const Error& e) {
      bad_declaration(script, "the default of parameter '" + name + "' is invalid: " + e.info().message);
    }
  }
}

std::string describe_limits(const json& spec) {
  std::string s;
  if (spec.contains("min")) s += " ≥ " + spec["min"].dump();
  if (spec.contains("max")) s += (s.empty() ? " " : " and ") + std::string("≤ ") + spec["max"].dump();
  return s;
}

void check_scalar(const std::string& script, const std::string& what, const std::string& type, const json& spec,
                  const json& value) {
  auto fail = [&](const std::string& why) {
    throw Error(ErrorClass::bad_parameter, "params." + what + " " + why + " (campaign " + script + ")",
                spec.value("description", std::string()));
  };
  if (type == "integer") {
    if (!value.is_number_integer() && !(value.is_number_float() && std::floor(value.get<double>()) == value.get<double>())) {
      fail("must be an integer" + describe_limits(spec));
    }
  } else if (type == "number") {
    if (!value.is_number() || !std::isfinite(value.get<double>())) fail("must be a number" + describe_limits(spec));
  } else if (type == "string") {
    if (!value.is_string()) fail("must be a string");
  } else if (type == "boolean") {
    if (!value.is_boolean()) fail("must be true or false");
  }
  if (value.is_number()) {
    double v = value.get<double>();
    if (spec.contains("min") && v < spec["min"].get<double>()) fail("must be" + describe_limits(spec) + ", got " + value.dump());
    if (spec.contains("max") && v > spec["max"].get<double>()) fail("must be" + describe_limits(spec) + ", got " + value.dump());
  }
  if (spec.contains("values") && !spec["values"].empty()) {
    const auto& values = spec["values"];
    if (std::find(values.begin(), values.end(), value) == values.end()) fail("must be one of " + values.dump() + ", got " + value.dump());
  }
}

}  // namespace

json CampaignScript::validate(const json& params) const {
  if (!params.is_object()) throw Error(ErrorClass::bad_parameter, "params must be a JSON object");
  for (const auto& [key, value] : params.items()) {
    if (!parameters.contains(key)) {
      std::string known;
      for (const auto& [k, v] : parameters.items()) known += (known.empty() ? "" : ", ") + k;
      throw Error(ErrorClass::bad_parameter, "unknown parameter params." + key + " for " + name,
                  known.empty() ? "this campaign takes no parameters" : "parameters: " + known);
    }
  }
  json out = json::object();
  for (const auto& [key, spec] : parameters.items()) {
    json value = params.contains(key) ? params[key] : spec["default"];
    if (value.is_null()) {
      out[key] = nullptr;
      continue;
    }
    std::string type = spec["type"];
    if (type == "array") {
      if (value.is_object() && value.empty()) value = json::array();  // Lua's {} has no array/object distinction
      if (!value.is_array()) {
        throw Error(ErrorClass::bad_parameter, "params." + key + " must be a list (campaign " + name + ")",
                    spec.value("description", std::string()));
      }
      auto size = static_cast<double>(value.size());
      if ((spec.contains("min_items") && size < spec["min_items"].get<double>()) ||
          (spec.contains("max_items") && size > spec["max_items"].get<double>())) {
        throw Error(ErrorClass::bad_parameter, "params." + key + " must have " +
                                                   (spec.contains("min_items") ? "at least " + spec["min_items"].dump() : std::string()) +
                                                   (spec.contains("max_items") ? " at most " + spec["max_items"].dump() : std::string()) +
                                                   " items (campaign " + name + ")");
      }
      for (std::size_t i = 0; i < value.size(); ++i) {
        check_scalar(name, key + "[" + std::to_string(i) + "]", spec["items"], spec, value[i]);
      }
    } else {
      check_scalar(name, key, type, spec, value);
      if (type == "integer" && value.is_number_float()) value = static_cast<std::int64_t>(value.get<double>());
    }
    out[key] = value;
  }
  return out;
}

json CampaignScript::to_json() const {
  return {
      {"name", name},
      {"kind", "campaign"},
      {"description", description},
      {"needs", needs},
      {"parameters", parameters},
      {"origin", origin},
      {"sha256", sha256},
      {"path", path.string()},
  };
}

CampaignScript parse_campaign_script(const std::string& name, const std::string& source) {
  CampaignScript s;
  s.name = name;
  s.source = source;
  s.sha256 = sha256_hex(source);
  ScriptLimits declaration_limits;
  declaration_limits.instruction_budget = 50'000'000;
  LuaSandbox sandbox(name + ".lua", declaration_limits, 0);
  lua_State* L = sandbox.state();
  install_lab_api(L, nullptr);
  sandbox.run_chunk(source);
  if (!lua_istable(L, -1)) bad_declaration(name, "the script must end with `return { ... }` describing the campaign");
  lua_getfield(L, -1, "run");
  if (!lua_isfunction(L, -1)) bad_declaration(name, "the returned table needs a `run = function(p) ... end`");
  lua_pop(L, 1);
  lua_pushnil(L);
  lua_setfield(L, -2, "run");  // the rest is plain data
  json decl = to_json(L, -1, name + " declaration");
  lua_pop(L, 1);
  if (!decl.is_object()) decl = json::object();
  if (decl.contains("name") && decl["name"] != name) {
    bad_declaration(name, "declares name '" + decl["name"].dump() + "' but its file is " + name + ".lua");
  }
  if (decl.contains("description") && !decl["description"].is_string()) bad_declaration(name, "`description` must be a string");
  s.description = decl.value("description", std::string());
  // Lua cannot tell an empty list from an empty table: `needs = {}` arrives as {}.
  if (decl.contains("needs") && decl["needs"].is_object() && decl["needs"].empty()) decl["needs"] = json::array();
  if (decl.contains("needs")) {
    if (!decl["needs"].is_array()) bad_declaration(name, "`needs` must be a list of roles");
    for (const auto& role : decl["needs"]) {
      std::string r = role.is_string() ? role.get<std::string>() : role.dump();
      if (std::find(std::begin(kRoles), std::end(kRoles), r) == std::end(kRoles)) {
        bad_declaration(name, "needs unknown role '" + r +
                                  "'; roles: luminance_meter, spectrophotometer, table, lamps, dimmer, camera");
      }
      s.needs.push_back(r);
    }
  }
  if (decl.contains("parameters") && decl["parameters"].is_array() && decl["parameters"].empty()) {
    decl["parameters"] = json::object();
  }
  if (decl.contains("parameters")) {
    if (!decl["parameters"].is_object()) bad_declaration(name, "`parameters` must be a table of name = {type = ...}");
    s.parameters = decl["parameters"];
    for (auto& [key, spec] : s.parameters.items()) check_parameter_spec(name, key, spec);
  }
  if (decl.contains("limits")) {
    const auto& l = decl["limits"];
    if (l.contains("memory_mib")) {
      double mib = l["memory_mib"].is_number() ? l["memory_mib"].get<double>() : -1;
      if (!(mib >= 1 && mib <= 1024)) bad_declaration(name, "limits.memory_mib must be from 1 to 1024");
      s.limits.memory_bytes = static_cast<std::size_t>(mib) << 20;
    }
    if (l.contains("instruction_budget")) {
      double b = l["instruction_budget"].is_number() ? l["instruction_budget"].get<double>() : -1;
      if (!(b >= 1e5 && b <= 1e11)) bad_declaration(name, "limits.instruction_budget must be from 1e5 to 1e11");
      s.limits.instruction_budget = static_cast<std::uint64_t>(b);
    }
  }
  return s;
}

}  // namespace colorlab::campaigns
