#include "colorlab/daemon/campaign_request.hpp"

#include "colorlab/core/error.hpp"

namespace colorlab::daemon {

CampaignRequest validate_campaign_params(campaigns::ScriptCatalogue& catalogue, const std::string& campaign,
                                         const nlohmann::json& params) {
  catalogue.refresh();
  auto script = catalogue.find(campaign);
  if (!script) {
    std::string names;
    for (const auto& c : catalogue.all()) names += (names.empty() ? "" : ", ") + c->name;
    throw Error(ErrorClass::not_found, "no campaign named '" + campaign + "'", "campaigns: " + names);
  }
  return CampaignRequest{script, script->validate(params)};
}

CampaignRequest validate_campaign_request(campaigns::ScriptCatalogue& catalogue, const campaigns::Lab& lab,
                                          const std::string& campaign, const nlohmann::json& params) {
  CampaignRequest request = validate_campaign_params(catalogue, campaign, params);
  lab.check_needs(request.script->needs);
  return request;
}

}  // namespace colorlab::daemon
