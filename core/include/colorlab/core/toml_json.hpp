#pragma once
// A TOML value as JSON, for configuration tables that are passed through to their consumer
// (driver options, simulator faults). Header-only: include it only from targets that link toml++.
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>
#include <toml++/toml.h>

namespace colorlab {

inline nlohmann::json toml_to_json(const toml::node& node) {
  if (auto t = node.as_table()) {
    nlohmann::json j = nlohmann::json::object();
    for (const auto& [k, v] : *t) j[std::string(k.str())] = toml_to_json(v);
    return j;
  }
  if (auto a = node.as_array()) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& v : *a) j.push_back(toml_to_json(v));
    return j;
  }
  if (node.is_boolean()) return *node.value<bool>();
  if (node.is_integer()) return *node.value<std::int64_t>();
  if (node.is_floating_point()) return *node.value<double>();
  if (auto v = node.value<std::string>()) return *v;
  return nullptr;
}

}  // namespace colorlab
