#pragma once
// §6.1.3's image-averaging study as a campaign: capture N frames of a uniform region, average the
// first 1, 2, 4, 8, 16, 25 of them, and record the spatial standard deviation of each average per
// CFA channel (Table 2's layout). Noise falls as 1/√N until the fixed pattern (PRNU, the patch
// itself) is all that is left, which tells the lab how many frames are worth taking.
#include "colorlab/campaigns/campaign.hpp"

namespace colorlab::campaigns {

class ImageAveraging final : public Campaign {
 public:
  std::string name() const override { return "image-averaging"; }
  std::string description() const override {
    return "Noise vs number of averaged frames (dissertation Table 2) on a region of a camera image";
  }
  nlohmann::json parameters() const override;
  void validate(const nlohmann::json& params) const override;
  boost::asio::awaitable<nlohmann::json> run(CampaignContext& ctx) const override;
};

}  // namespace colorlab::campaigns
