#pragma once
// Where campaigns come from: the shipped scripts installed with the program and the lab's own
// directory. refresh() re-reads a file only when its size or mtime changed, so a script dropped in
// (or edited) is picked up by the next request without a restart. A script that fails to parse is
// listed with its error instead of silently disappearing. NAME.sequence.lua files are sequences
// (sequence.hpp): campaigns queued together; a sequence may not share a campaign's name.
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "colorlab/campaigns/script.hpp"
#include "colorlab/campaigns/sequence.hpp"

namespace colorlab::campaigns {

struct CampaignDirectory {
  std::filesystem::path path;
  std::string origin;  // "shipped" or "lab"
};

struct BrokenScript {
  std::filesystem::path path;
  std::string error;
};

class ScriptCatalogue {
 public:
  // Later directories win over earlier ones for the same name (the lab may override a shipped script).
  explicit ScriptCatalogue(std::vector<CampaignDirectory> directories);

  void refresh();
  std::shared_ptr<const CampaignScript> find(const std::string& name) const;
  std::vector<std::shared_ptr<const CampaignScript>> all() const;
  std::shared_ptr<const CampaignSequence> find_sequence(const std::string& name) const;
  std::vector<std::shared_ptr<const CampaignSequence>> sequences() const;
  const std::vector<BrokenScript>& broken() const { return broken_; }
  const std::vector<CampaignDirectory>& directories() const { return directories_; }

 private:
  struct Cached {
    std::filesystem::file_time_type mtime;
    std::uintmax_t size = 0;
    std::shared_ptr<const CampaignScript> script;
    std::shared_ptr<const CampaignSequence> sequence;
    std::string error;
  };
  std::vector<CampaignDirectory> directories_;
  std::map<std::filesystem::path, Cached> cache_;
  std::map<std::string, std::shared_ptr<const CampaignScript>> by_name_;
  std::map<std::string, std::shared_ptr<const CampaignSequence>> sequences_;
  std::vector<BrokenScript> broken_;
};

// The shipped scripts' directory: <exe>/../share/colorlab/campaigns (build tree and installed alike),
// or $COLORLAB_CAMPAIGNS_DIR.
std::filesystem::path shipped_campaign_dir();

}  // namespace colorlab::campaigns
