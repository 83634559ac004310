#pragma once
// Shared by the resume tests: a colorlabd with its embedded simulated lab on a fresh state
// directory, and the checks every kill -9 test makes.
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "colorlab/client/api_client.hpp"
#include "colorlab/client/runs.hpp"
#include "colorlab/testing/daemon.hpp"
#include "colorlab/testing/temp_dir.hpp"

namespace colorlab::testing {

// Writes <dir>/colorlabd.toml: embedded simulated lab at `time_scale`, plus `extra` TOML. Without
// `camera`, the simulated lab starts no GigE Vision camera: only one can serve 127.0.0.1, and tests
// that need it hold the ctest lock gigevision_loopback.
std::filesystem::path write_daemon_config(const std::filesystem::path& dir, double time_scale, std::uint64_t seed,
                                          const std::string& extra = {}, bool camera = false);
client::ApiClient api_for(const DaemonProcess& daemon);
// Installs a campaign script as <dir>/state/campaigns/<file_name>, where the daemon of write_daemon_config(dir, …)
// finds it. Throws when it cannot be written: a test would otherwise fail later, at a campaign the daemon lacks.
void write_campaign(const std::filesystem::path& dir, const std::string& file_name, std::string_view source);
// Polls the execution until it is terminal; returns its last state.
nlohmann::json wait_terminal(const client::ApiClient& api, const std::string& execution_id,
                             std::chrono::seconds timeout = std::chrono::seconds(90));
// PRAGMA integrity_check of the daemon's database (the daemon must be stopped): "ok" or what is wrong.
std::string integrity_check(const std::filesystem::path& state_dir);

// Starts the campaign, waits for it (expecting finished_ok) and returns its run with the measurements.
nlohmann::json run_to_end(const client::ApiClient& api, const std::string& campaign, const nlohmann::json& params,
                          std::chrono::seconds timeout = std::chrono::seconds(120));

// kill -9 at random moments of a campaign on the embedded simulated lab: the execution completes by
// itself after each restart, the database is whole, and the stored steps are exactly those of an
// uninterrupted run on a fresh daemon, each value within `tolerance` of that run's.
struct KillNineCase {
  std::string campaign;
  nlohmann::json params = nlohmann::json::object();
  double time_scale = 100;
  std::uint64_t seed = 5;
  // Each of (at most) two kills per run comes 50..max_delay_ms after the previous start; 0 = 90 % of what the
  // uninterrupted run took (a moment anywhere in it, however fast the machine).
  int max_delay_ms = 2500;
  int runs = 3;          // interrupted runs, each on a fresh daemon with its own random moments
  std::string lab_toml;  // the simulated lab's configuration, when not write_daemon_config's
  // On each fresh daemon before the campaign starts (not interrupted): parameters to add, e.g. the id of
  // a chart-read run the campaign reads.
  std::function<nlohmann::json(const client::ApiClient&)> prepare;
  // How far a measurement's value may lie from the uninterrupted run's value of the same step.
  std::function<double(const nlohmann::json& measurement, double reference_value)> tolerance;
  std::chrono::seconds timeout = std::chrono::seconds(180);
};
void kill_and_compare(const KillNineCase& c);

}  // namespace colorlab::testing
