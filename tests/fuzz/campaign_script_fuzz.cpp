// A campaign script's declaration (campaigns/ script.cpp): Lua source run at its top level inside
// the declaration sandbox with its memory cap and instruction budget, its returned table read into
// name, needs, parameters and limits, each parameter's own default checked against its own limits;
// then the defaults validated as an empty `params` would be.
#include "colorlab/campaigns/script.hpp"
#include "fuzz_support.hpp"

namespace {

using colorlab::fuzz::typed;

void one_input(const std::uint8_t* data, std::size_t size) {
  colorlab::campaigns::CampaignScript script;
  const std::string source(colorlab::fuzz::as_text(data, size));
  if (!typed("parse_campaign_script", [&] { script = colorlab::campaigns::parse_campaign_script("fuzz", source); })) return;
  (void)script.to_json().dump();
  typed("CampaignScript::validate", [&] { (void)script.validate(nlohmann::json::object()); });
}

}  // namespace

COLORLAB_FUZZ_TARGET("campaign_script", one_input)
