#include "colorlab/campaigns/catalogue.hpp"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "colorlab/core/error.hpp"
#include "colorlab/core/log.hpp"

namespace colorlab::campaigns {

namespace fs = std::filesystem;

std::filesystem::path shipped_campaign_dir() {
  if (const char* env = std::getenv("COLORLAB_CAMPAIGNS_DIR"); env && *env) return env;
  std::error_code ec;
  auto self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return "share/colorlab/campaigns";
  return self.parent_path().parent_path() / "share" / "colorlab" / "campaigns";
}

ScriptCatalogue::ScriptCatalogue(std::vector<CampaignDirectory> directories) : directories_(std::move(directories)) {
  refresh();
}

void ScriptCatalogue::refresh() {
  std::map<std::string, std::shared_ptr<const CampaignScript>> by_name;
  std::map<std::string, std::shared_ptr<const CampaignSequence>> sequences;
  std::vector<BrokenScript> broken;
  std::map<fs::path, Cached> seen;
  for (const auto& dir : directories_) {
    std::error_code ec;
    if (!fs::is_directory(dir.path, ec)) continue;
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(dir.path, ec)) {
      if (entry.path().extension() == ".lua" && entry.is_regular_file(ec)) files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end());
    for (const auto& file : files) {
      auto mtime = fs::last_write_time(file, ec);
      auto size = fs::file_size(file, ec);
      if (ec) continue;
      auto it = cache_.find(file);
      Cached c;
      if (it != cache_.end() && it->second.mtime == mtime && it->second.size == size) {
        c = it->second;
      } else {
        c.mtime = mtime;
        c.size = size;
        std::ifstream in(file, std::ios::binary);
        std::stringstream text;
        text << in.rdbuf();
        std::string filename = file.filename().string();
        bool is_sequence = filename.size() > std::string(kSequenceSuffix).size() &&
                           filename.ends_with(kSequenceSuffix);
        try {
          if (is_sequence) {
            auto sequence = std::make_shared<CampaignSequence>(parse_campaign_sequence(
                filename.substr(0, filename.size() - std::string(kSequenceSuffix).size()), text.str()));
            sequence->path = file;
            sequence->origin = dir.origin;
            c.sequence = sequence;
          } else {
            auto script = std::make_shared<CampaignScript>(parse_campaign_script(file.stem().string(), text.str()));
            script->path = file;
            script->origin = dir.origin;
            c.script = script;
          }
        } catch (const Error& e) {
          c.error = e.what();
          log::warning("campaigns", file.string() + ": " + e.what());
        }
      }
      if (c.script) {
        by_name[c.script->name] = c.script;
      } else if (c.sequence) {
        sequences[c.sequence->name] = c.sequence;
      } else {
        broken.push_back({file, c.error});
      }
      seen[file] = std::move(c);
    }
  }
  // One name, one thing to queue: a sequence named like a campaign is listed as broken.
  for (auto it = sequences.begin(); it != sequences.end();) {
    if (by_name.count(it->first)) {
      broken.push_back({it->second->path, "sequence '" + it->first + "' has the name of a campaign; rename one"});
      it = sequences.erase(it);
    } else {
      ++it;
    }
  }
  cache_ = std::move(seen);
  sequences_ = std::move(sequences);
  by_name_ = std::move(by_name);
  broken_ = std::move(broken);
}

std::shared_ptr<const CampaignScript> ScriptCatalogue::find(const std::string& name) const {
  auto it = by_name_.find(name);
  return it == by_name_.end() ? nullptr : it->second;
}

std::vector<std::shared_ptr<const CampaignScript>> ScriptCatalogue::all() const {
  std::vector<std::shared_ptr<const CampaignScript>> out;
  for (const auto& [name, s] : by_name_) out.push_back(s);
  return out;
}

std::shared_ptr<const CampaignSequence> ScriptCatalogue::find_sequence(const std::string& name) const {
  auto it = sequences_.find(name);
  return it == sequences_.end() ? nullptr : it->second;
}

std::vector<std::shared_ptr<const CampaignSequence>> ScriptCatalogue::sequences() const {
  std::vector<std::shared_ptr<const CampaignSequence>> out;
  for (const auto& [name, s] : sequences_) out.push_back(s);
  return out;
}

}  // namespace colorlab::campaigns
