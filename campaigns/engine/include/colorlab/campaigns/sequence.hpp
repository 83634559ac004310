#pragma once
// A sequence: campaigns queued together, in order, as one group (issue 11's `dissertation`). A file
// NAME.sequence.lua in a campaigns directory returns a data-only table, read through the same sandbox
// as a campaign's declaration:
//   return { description = "...",
//            steps = { { name = "chart-read", campaign = "chart-read", params = { chart = "sg" }, covers = "..." },
//                      { name = "characterize-camera", campaign = "characterize-camera", params = { ... },
//                        reference = { param = "reference_run", step = "chart-read" } } },
//            small = { ["characterize-camera"] = { frames = 2 } } }
// A step's reference names an earlier step whose run the parameter takes: queued, it is
// {"$run_of": "<that step's item id>"} (store/queue.hpp). `small` is the reduced variant's overrides.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace colorlab::campaigns {

struct SequenceStep {
  std::string name;  // unique within the sequence
  std::string campaign;
  nlohmann::json params = nlohmann::json::object();
  std::optional<std::string> reference_param, reference_step;  // both or neither
  std::string covers;                                          // what of the report the step is for
  nlohmann::json to_json() const;
};

struct CampaignSequence {
  std::string name;  // the file's stem without ".sequence"
  std::filesystem::path path;
  std::string origin;  // "shipped" or "lab"
  std::string sha256;
  std::string description;
  std::vector<SequenceStep> steps;
  nlohmann::json small = nlohmann::json::object();  // step -> params overriding for the small variant

  // GET /v1/campaigns's view: kind "sequence", its steps with their parameters, the small overrides.
  nlohmann::json to_json() const;
  // The steps with the small overrides (if asked) and then `overrides` ({step: {key: value}}) applied.
  // Throws Error{bad_parameter} for an override of a step the sequence does not have, or one that
  // sets a step's reference parameter (the sequence fills it in).
  std::vector<SequenceStep> expand(bool use_small, const nlohmann::json& overrides) const;
};

inline constexpr const char* kSequenceSuffix = ".sequence.lua";

// Runs the file's top level in a sandbox and reads the table. Throws Error{script_error} naming the
// file for a sequence that does not compile or is malformed (unknown step in a reference or in small,
// a reference to a later step, a duplicate step name).
CampaignSequence parse_campaign_sequence(const std::string& name, const std::string& source);

}  // namespace colorlab::campaigns
