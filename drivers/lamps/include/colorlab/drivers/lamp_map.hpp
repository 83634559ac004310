#pragma once
// Which output (relay number or DMX channel) lights which cabinet lamp, and the rule that at most
// one lamp is lit unless the configuration says otherwise: mixing D65 with TL84 silently would
// spoil every measurement of the night.
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace colorlab::drivers {

class LampMap {
 public:
  LampMap() = default;
  // `outputs`: lamp name → 1-based output number. Throws Error{bad_parameter} for an empty map,
  // an output outside 1..max_output, or two lamps on the same output.
  LampMap(std::map<std::string, int> outputs, int max_output, bool allow_multiple);
  // {"D65": 1, "TL84": 2, ...}
  static LampMap from_json(const nlohmann::json& j, int max_output, bool allow_multiple);

  std::vector<std::string> names() const;
  int output(const std::string& lamp) const;  // throws bad_parameter naming the known lamps
  bool allow_multiple() const { return allow_multiple_; }

  // The outputs to light for `on`; throws Error{conflict} for two lamps when not allowed.
  std::vector<int> outputs_for(const std::vector<std::string>& on) const;

 private:
  std::map<std::string, int> outputs_;
  int max_output_ = 0;
  bool allow_multiple_ = false;
};

}  // namespace colorlab::drivers
