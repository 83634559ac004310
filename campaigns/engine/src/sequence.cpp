#include "colorlab/campaigns/sequence.hpp"

#include <map>
#include <set>

#include <lua5.4/lua.hpp>

#include "colorlab/campaigns/lua_sandbox.hpp"
#include "colorlab/campaigns/lua_value.hpp"
#include "colorlab/campaigns/script.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::campaigns {

using nlohmann::json;

namespace {

[[noreturn]] void bad_sequence(const std::string& name, const std::string& what) {
  throw Error(ErrorClass::script_error, name + kSequenceSuffix + ": " + what,
              "a sequence returns { description = ..., steps = { { name =, campaign =, params =, reference = } }, "
              "small = { [step] = { ... } } }");
}

// Lua cannot tell an empty list from an empty table: `params = {}` may arrive as [].
json object_or_empty(const json& v) { return v.is_array() && v.empty() ? json::object() : v; }

std::string text_field(const std::string& name, const json& obj, const char* key, const std::string& where) {
  if (!obj.contains(key) || !obj[key].is_string() || obj[key].get<std::string>().empty()) {
    bad_sequence(name, where + " needs a string `" + key + "`");
  }
  return obj[key].get<std::string>();
}

}  // namespace

json SequenceStep::to_json() const {
  json j{{"name", name}, {"campaign", campaign}, {"params", params}, {"covers", covers}};
  j["reference"] = reference_param ? json{{"param", *reference_param}, {"step", *reference_step}} : json(nullptr);
  return j;
}

json CampaignSequence::to_json() const {
  json steps_json = json::array();
  for (const auto& s : steps) steps_json.push_back(s.to_json());
  return {
      {"name", name},
      {"kind", "sequence"},
      {"description", description},
      {"origin", origin},
      {"sha256", sha256},
      {"path", path.string()},
      {"steps", steps_json},
      {"small", small},
      {"needs", json::array()},
      {"parameters", json::object()},
  };
}

std::vector<SequenceStep> CampaignSequence::expand(bool use_small, const json& overrides) const {
  if (!overrides.is_null() && !overrides.is_object()) {
    throw Error(ErrorClass::bad_parameter, "overrides must be an object {step: {key: value}}",
                "e.g. {\"cabinet-grid\": {\"rows\": 2}}");
  }
  std::map<std::string, const SequenceStep*> by_name;
  for (const auto& s : steps) by_name[s.name] = &s;
  if (overrides.is_object()) {
    for (const auto& [step, values] : overrides.items()) {
      auto it = by_name.find(step);
      if (it == by_name.end()) {
        std::string names;
        for (const auto& s : steps) names += (names.empty() ? "" : ", ") + s.name;
        throw Error(ErrorClass::bad_parameter, "sequence " + name + " has no step '" + step + "'", "steps: " + names);
      }
      if (!values.is_object()) {
        throw Error(ErrorClass::bad_parameter, "the overrides of step '" + step + "' must be an object {key: value}");
      }
      if (it->second->reference_param && values.contains(*it->second->reference_param)) {
        throw Error(ErrorClass::bad_parameter,
                    "step '" + step + "''s parameter '" + *it->second->reference_param + "' is the run of step '" +
                        *it->second->reference_step + "': the sequence fills it in",
                    "queue the campaign by itself to give it another run");
      }
    }
  }
  std::vector<SequenceStep> out;
  for (auto s : steps) {
    if (use_small && small.contains(s.name)) s.params.update(small[s.name]);
    if (overrides.is_object() && overrides.contains(s.name)) s.params.update(overrides[s.name]);
    out.push_back(std::move(s));
  }
  return out;
}

CampaignSequence parse_campaign_sequence(const std::string& name, const std::string& source) {
  CampaignSequence seq;
  seq.name = name;
  seq.sha256 = sha256_hex(source);
  ScriptLimits limits;
  limits.instruction_budget = 10'000'000;
  limits.memory_bytes = 8u << 20;
  LuaSandbox sandbox(name + kSequenceSuffix, limits, 0);
  lua_State* L = sandbox.state();
  sandbox.run_chunk(source);
  if (!lua_istable(L, -1)) bad_sequence(name, "the file must end with `return { steps = { ... } }`");
  json decl = to_json(L, -1, name + " sequence");
  lua_pop(L, 1);
  if (!decl.is_object()) bad_sequence(name, "the returned table must have named fields");
  for (const auto& [key, value] : decl.items()) {
    if (key != "description" && key != "steps" && key != "small") {
      bad_sequence(name, "unknown field `" + key + "` (description, steps, small)");
    }
  }
  if (decl.contains("description")) {
    if (!decl["description"].is_string()) bad_sequence(name, "`description` must be a string");
    seq.description = decl["description"].get<std::string>();
  }
  if (!decl.contains("steps") || !decl["steps"].is_array() || decl["steps"].empty()) {
    bad_sequence(name, "`steps` must be a non-empty list");
  }
  std::set<std::string> seen;
  for (const auto& raw : decl["steps"]) {
    std::string where = "step " + std::to_string(seq.steps.size() + 1);
    if (!raw.is_object()) bad_sequence(name, where + " must be a table");
    for (const auto& [key, value] : raw.items()) {
      if (key != "name" && key != "campaign" && key != "params" && key != "reference" && key != "covers") {
        bad_sequence(name, where + ": unknown field `" + key + "` (name, campaign, params, reference, covers)");
      }
    }
    SequenceStep step;
    step.name = text_field(name, raw, "name", where);
    where = "step '" + step.name + "'";
    if (!seen.insert(step.name).second) bad_sequence(name, "two steps are named '" + step.name + "'");
    step.campaign = text_field(name, raw, "campaign", where);
    step.params = object_or_empty(raw.value("params", json::object()));
    if (!step.params.is_object()) bad_sequence(name, where + ": `params` must be a table of parameters");
    if (raw.contains("covers")) {
      if (!raw["covers"].is_string()) bad_sequence(name, where + ": `covers` must be a string");
      step.covers = raw["covers"].get<std::string>();
    }
    if (raw.contains("reference")) {
      const auto& ref = raw["reference"];
      if (!ref.is_object()) bad_sequence(name, where + ": `reference` must be { param = ..., step = ... }");
      step.reference_param = text_field(name, ref, "param", where + "'s reference");
      step.reference_step = text_field(name, ref, "step", where + "'s reference");
      bool earlier = false;
      for (const auto& s : seq.steps) earlier = earlier || s.name == *step.reference_step;
      if (!earlier) bad_sequence(name, where + " references '" + *step.reference_step + "', which is not an earlier step");
      if (step.params.contains(*step.reference_param)) {
        bad_sequence(name, where + " sets `" + *step.reference_param + "`, which its reference fills in");
      }
    }
    seq.steps.push_back(std::move(step));
  }
  if (decl.contains("small")) {
    json small = object_or_empty(decl["small"]);
    if (!small.is_object()) bad_sequence(name, "`small` must be a table { [step] = { key = value } }");
    for (auto& [step, values] : small.items()) {
      if (!seen.count(step)) bad_sequence(name, "`small` names step '" + step + "', which the sequence does not have");
      values = object_or_empty(values);
      if (!values.is_object()) bad_sequence(name, "`small`'s '" + step + "' must be a table of parameters");
    }
    seq.small = small;
  }
  return seq;
}

}  // namespace colorlab::campaigns
