#pragma once
// colorlabd's configuration: a TOML file (see docs/configuration.md), or the embedded default
// that starts the simulated lab. Command-line flags override both.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "colorlab/drivers/factory.hpp"

namespace colorlab::daemon {

struct SimulatorConfig {
  bool enabled = false;                       // start colorlab-sim as a child process
  std::optional<std::filesystem::path> config;  // its TOML; none = the default lab
  std::optional<double> time_scale;
  std::optional<std::uint64_t> seed;
};

struct DaemonConfig {
  std::filesystem::path state_dir = "./colorlab-state";
  std::string listen_host = "127.0.0.1";
  unsigned short listen_port = 8765;
  std::optional<std::filesystem::path> unix_socket;  // default: <state_dir>/colorlabd.sock
  std::vector<drivers::InstrumentConfig> instruments;
  SimulatorConfig simulator;

  std::filesystem::path database_path() const;
  std::filesystem::path socket_path() const;
};

// The configuration colorlabd uses without --config: the simulated lab, state under ./colorlab-state.
DaemonConfig embedded_default_config();
// Throws Error{bad_parameter} naming the file, line and key for anything invalid.
DaemonConfig load_config(const std::filesystem::path& file);
// "HOST:PORT" → host and port; throws Error{bad_parameter}.
void apply_listen(DaemonConfig& c, const std::string& host_port);

}  // namespace colorlab::daemon
