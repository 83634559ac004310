#pragma once
// colorlab's HTTP API, v1: the single source of names both colorlabd and the client use.
// docs/API.md describes every route and body; change them together.
#include <string_view>

namespace colorlab::protocol {

inline constexpr std::string_view kApiVersion = "1";
inline constexpr std::string_view kPrefix = "/v1";

inline constexpr std::string_view kContentJson = "application/json";
inline constexpr std::string_view kContentProblem = "application/problem+json";

// Requests larger than this are refused with 413 before they are read.
inline constexpr std::size_t kMaxRequestBody = 1 << 20;
inline constexpr unsigned kDefaultPageLimit = 50;
inline constexpr unsigned kMaxPageLimit = 300;
// A run's measurements are small rows read in bulk (a cabinet grid holds thousands).
inline constexpr unsigned kDefaultMeasurementPageLimit = 1000;
inline constexpr unsigned kMaxMeasurementPageLimit = 5000;

// Default endpoints of the embedded (simulated-lab) configuration.
inline constexpr std::string_view kDefaultListen = "127.0.0.1:8765";
inline constexpr std::string_view kDefaultStateDir = "./colorlab-state";
inline constexpr std::string_view kSocketName = "colorlabd.sock";
inline constexpr std::string_view kDatabaseName = "colorlab.db";

}  // namespace colorlab::protocol
