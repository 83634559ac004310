#pragma once
// The simplest campaign: N luminance readings of the spot the meter is aimed at, with their
// mean and standard deviation. It is the default campaign of the Quick start.
#include "colorlab/campaigns/campaign.hpp"

namespace colorlab::campaigns {

class LuminanceSpot final : public Campaign {
 public:
  std::string name() const override { return "luminance-spot"; }
  std::string description() const override {
    return "Spot luminance with the LS-110: N readings of the aimed spot, their mean and standard deviation";
  }
  nlohmann::json parameters() const override;
  void validate(const nlohmann::json& params) const override;
  boost::asio::awaitable<nlohmann::json> run(CampaignContext& ctx) const override;
};

}  // namespace colorlab::campaigns
