#pragma once
// Human-readable renderings of API objects for the terminal; --json prints the objects instead.
#include <string>

#include <nlohmann/json.hpp>

namespace colorlab::cli {

// GET /v1, with GET /v1/shipping under "shipping" when the daemon has that route.
std::string format_status(const nlohmann::json& root);
std::string format_shipping(const nlohmann::json& shipping);
std::string format_instruments(const nlohmann::json& list);
std::string format_campaigns(const nlohmann::json& list);
std::string format_runs(const nlohmann::json& page);
std::string format_executions(const nlohmann::json& page);
std::string format_run(const nlohmann::json& run);
std::string format_execution(const nlohmann::json& execution);
std::string format_dry_run(const nlohmann::json& report);
std::string format_request(const nlohmann::json& request);
std::string format_requests(const nlohmann::json& list);
std::string format_queue(const nlohmann::json& queue);
std::string format_queue_item(const nlohmann::json& item);
std::string format_sequence(const nlohmann::json& sequence);
std::string format_queue_group(const nlohmann::json& group);

}  // namespace colorlab::cli
