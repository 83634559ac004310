#pragma once
// The checks a request to run a campaign passes before anything is stored or moves: the campaign
// exists (re-read from its directories), its parameters validate against the script's declaration
// (defaults filled in), and the lab has an instrument for every role it needs. Shared by
// Executions::start and the night's queue, so an item accepted into the queue was checked exactly
// as a direct start would check it.
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "colorlab/campaigns/catalogue.hpp"
#include "colorlab/campaigns/lab.hpp"

namespace colorlab::daemon {

struct CampaignRequest {
  std::shared_ptr<const campaigns::CampaignScript> script;
  nlohmann::json params;  // validated, defaults filled in
};

// The campaign and its parameters only (a dry run lists missing instruments instead of refusing).
CampaignRequest validate_campaign_params(campaigns::ScriptCatalogue& catalogue, const std::string& campaign,
                                         const nlohmann::json& params);

// Throws Error{not_found} for an unknown campaign (hint: the known ones) or a missing instrument,
// Error{bad_parameter} naming the parameter.
CampaignRequest validate_campaign_request(campaigns::ScriptCatalogue& catalogue, const campaigns::Lab& lab,
                                          const std::string& campaign, const nlohmann::json& params);

}  // namespace colorlab::daemon
