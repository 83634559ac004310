#pragma once
// Globally unique, time-ordered ids (UUIDv7) for runs and executions, so runs from several
// benches can later be merged without collisions, and ids sort by creation time.
#include <chrono>
#include <string>

namespace colorlab {

std::string new_uuid_v7();
// "2026-11-22T00:01:48.123Z"
std::string iso8601_utc(std::chrono::system_clock::time_point t);
inline std::string now_iso8601() { return iso8601_utc(std::chrono::system_clock::now()); }

}  // namespace colorlab
