#pragma once
// The yardstick for a lamp that drifts: what the luminance meter should read, where it is aimed now, under
// lamps the lab has found stable. A meter aimed by hand reads the same light again only at the same aim:
// between spots the cabinet's floor differs by tens of percent, and between dimmer levels by the dimmer's own
// (non-proportional) response, so neither can be predicted to a few percent. So the reference is kept per
// dimmer level: the level at which the lamps were found stable takes that reading, any other level its first
// reading since; a later reading at a level that differs from the level's reference by more than the
// tolerance is a drift. Forgotten when the lamps change; learned again when a person may have moved the meter.
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace colorlab::campaigns {

struct LightDrift {
  std::vector<std::string> lamps;
  double dimmer_percent = 0;
  double expected = 0;  // the level's reference
  double reading = 0;
  double change_pct = 0;  // (reading − expected) / expected, in %
};

class LightReference {
 public:
  explicit LightReference(double tolerance_pct) : tolerance_pct_(tolerance_pct) {}

  double tolerance_pct() const { return tolerance_pct_; }

  // The lamps were found stable at this dimmer level with this reading: a new yardstick (other levels are
  // learned again). With no lamp lit or no light there is nothing to hold a reading to.
  void stable(std::vector<std::string> lamps, double dimmer_percent, double luminance) {
    forget();
    if (lamps.empty() || !(luminance > 0)) return;
    lamps_ = std::move(lamps);
    levels_[dimmer_percent] = luminance;
  }

  // The lamps changed: nothing to compare with until they are found stable again.
  void forget() {
    lamps_.reset();
    levels_.clear();
  }

  // The meter may have been aimed elsewhere: the lamps are still stable, but every level's reference is learned
  // again from its first reading at the new aim.
  void moved() { levels_.clear(); }

  // The reference at this level under these lamps, if any.
  std::optional<double> expected(const std::vector<std::string>& lamps, double dimmer_percent) const {
    if (!lamps_ || *lamps_ != lamps) return std::nullopt;
    auto it = levels_.find(dimmer_percent);
    if (it == levels_.end()) return std::nullopt;
    return it->second;
  }

  // A reading under `lamps` at `dimmer_percent`: the drift when it differs from the level's reference by more
  // than the tolerance (the reference stays); otherwise nullopt, and a level not read since the lamps were
  // found stable takes this reading as its reference.
  std::optional<LightDrift> check(const std::vector<std::string>& lamps, double dimmer_percent, double luminance) {
    if (!lamps_ || *lamps_ != lamps) return std::nullopt;
    auto [it, first] = levels_.try_emplace(dimmer_percent, luminance);
    if (first || !(it->second > 0)) return std::nullopt;
    const double change_pct = (luminance - it->second) / it->second * 100;
    if (std::abs(change_pct) <= tolerance_pct_) return std::nullopt;
    return LightDrift{lamps, dimmer_percent, it->second, luminance, change_pct};
  }

  // After a suspension the light settled at `luminance` at this level under these lamps: it is the reference
  // from now on. The other levels' references are dropped and learned again from their next reading: a
  // drift that went unnoticed while they were first read may have moved them by anything up to the
  // tolerance. Returns the change in % of the level's old reference, or nullopt when it had none.
  std::optional<double> settle_at(const std::vector<std::string>& lamps, double dimmer_percent, double luminance) {
    auto before = expected(lamps, dimmer_percent);
    stable(lamps, dimmer_percent, luminance);
    if (!before || !(*before > 0) || !(luminance > 0)) return std::nullopt;
    return (luminance / *before - 1) * 100;
  }

 private:
  double tolerance_pct_;
  std::optional<std::vector<std::string>> lamps_;
  std::map<double, double> levels_;  // dimmer % → reading
};

}  // namespace colorlab::campaigns
