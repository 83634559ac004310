#pragma once
// Shared by the resume tests: a colorlabd with its embedded simulated lab on a fresh state
// directory, and the checks every kill -9 test makes.
#include <chrono>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "colorlab/client/api_client.hpp"
#include "colorlab/testing/daemon.hpp"
#include "colorlab/testing/temp_dir.hpp"

namespace colorlab::testing {

// Writes <dir>/colorlabd.toml: embedded simulated lab at `time_scale`, plus `extra` TOML. Without
// `camera`, the simulated lab starts no GigE Vision camera: only one can serve 127.0.0.1, and tests
// that need it hold the ctest lock gigevision_loopback.
std::filesystem::path write_daemon_config(const std::filesystem::path& dir, double time_scale, std::uint64_t seed,
                                          const std::string& extra = {}, bool camera = false);
client::ApiClient api_for(const DaemonProcess& daemon);
// Polls the execution until it is terminal; returns its last state.
nlohmann::json wait_terminal(const client::ApiClient& api, const std::string& execution_id,
                             std::chrono::seconds timeout = std::chrono::seconds(90));
// PRAGMA integrity_check of the daemon's database (the daemon must be stopped): "ok" or what is wrong.
std::string integrity_check(const std::filesystem::path& state_dir);

}  // namespace colorlab::testing
