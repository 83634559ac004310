#pragma once
// colorlab doctor's report as text for the operator (the --json report is the same content).
#include <string>

#include <nlohmann/json.hpp>

namespace colorlab::cli {

std::string render_report(const nlohmann::json& report);

}  // namespace colorlab::cli
