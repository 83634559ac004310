#include "colorlab/campaigns/campaign.hpp"
#include "colorlab/campaigns/image_averaging.hpp"
#include "colorlab/campaigns/luminance_spot.hpp"

namespace colorlab::campaigns {

CampaignRegistry CampaignRegistry::with_builtin_campaigns() {
  CampaignRegistry r;
  r.add(std::make_unique<LuminanceSpot>());
  r.add(std::make_unique<ImageAveraging>());
  return r;
}

void CampaignRegistry::add(std::unique_ptr<Campaign> c) { campaigns_.push_back(std::move(c)); }

const Campaign* CampaignRegistry::find(const std::string& name) const {
  for (const auto& c : campaigns_) {
    if (c->name() == name) return c.get();
  }
  return nullptr;
}

std::vector<const Campaign*> CampaignRegistry::all() const {
  std::vector<const Campaign*> out;
  for (const auto& c : campaigns_) out.push_back(c.get());
  return out;
}

}  // namespace colorlab::campaigns
