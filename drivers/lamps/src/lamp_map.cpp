#include "colorlab/drivers/lamp_map.hpp"

#include <set>

#include <nlohmann/json.hpp>

#include "colorlab/core/error.hpp"

namespace colorlab::drivers {

LampMap::LampMap(std::map<std::string, int> outputs, int max_output, bool allow_multiple)
    : outputs_(std::move(outputs)), max_output_(max_output), allow_multiple_(allow_multiple) {
  if (outputs_.empty()) throw Error(ErrorClass::bad_parameter, "lamp map is empty", "map each lamp name to an output number");
  std::set<int> used;
  for (const auto& [name, out] : outputs_) {
    if (out < 1 || out > max_output_) {
      throw Error(ErrorClass::bad_parameter,
                  "lamp '" + name + "' is on output " + std::to_string(out) + ", outside 1.." + std::to_string(max_output_));
    }
    if (!used.insert(out).second) {
      throw Error(ErrorClass::bad_parameter, "lamp '" + name + "' shares output " + std::to_string(out) + " with another lamp");
    }
  }
}

LampMap LampMap::from_json(const nlohmann::json& j, int max_output, bool allow_multiple) {
  if (!j.is_object()) throw Error(ErrorClass::bad_parameter, "lamp map must be an object {\"D65\": 1, ...}");
  std::map<std::string, int> outputs;
  for (const auto& [name, value] : j.items()) {
    if (!value.is_number_integer()) {
      throw Error(ErrorClass::bad_parameter, "lamp '" + name + "': output must be an integer, got " + value.dump());
    }
    outputs[name] = value.get<int>();
  }
  return LampMap(std::move(outputs), max_output, allow_multiple);
}

std::vector<std::string> LampMap::names() const {
  std::vector<std::string> out;
  for (const auto& [name, _] : outputs_) out.push_back(name);
  return out;
}

int LampMap::output(const std::string& lamp) const {
  auto it = outputs_.find(lamp);
  if (it == outputs_.end()) {
    std::string known;
    for (const auto& [name, _] : outputs_) known += (known.empty() ? "" : ", ") + name;
    throw Error(ErrorClass::bad_parameter, "unknown lamp '" + lamp + "'", "configured lamps: " + known);
  }
  return it->second;
}

std::vector<int> LampMap::outputs_for(const std::vector<std::string>& on) const {
  std::set<std::string> unique(on.begin(), on.end());
  if (unique.size() > 1 && !allow_multiple_) {
    std::string list;
    for (const auto& n : unique) list += (list.empty() ? "" : " + ") + n;
    throw Error(ErrorClass::conflict, "refusing to light " + list + " at once",
                "set allow_multiple_lamps = true in the lamp controller's options if mixing is intended");
  }
  std::vector<int> outs;
  for (const auto& n : unique) outs.push_back(output(n));
  return outs;
}

}  // namespace colorlab::drivers
