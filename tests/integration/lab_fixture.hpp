#pragma once
// colorlab-sim and colorlabd as real processes, wired the way a lab runs them: the daemon is
// configured with the simulator's serial ports, and the CLI talks to the daemon.
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "colorlab/testing/process.hpp"
#include "colorlab/testing/temp_dir.hpp"

namespace colorlab::testing {

// A colorlab-sim configuration with every instrument but the GigE Vision camera.
std::string write_sim_config_without_camera(const std::filesystem::path& dir);

class LabFixture {
 public:
  explicit LabFixture(double time_scale = 20, std::string ls110_options = "{ reply_timeout_ms = 1500 }");
  ~LabFixture();

  void start_daemon();
  void kill_daemon();  // SIGKILL, no cleanup

  nlohmann::json sim_control(const nlohmann::json& command);
  // Runs the `colorlab` CLI against the daemon, over its Unix socket (every scope).
  RunResult cli(std::vector<std::string> args, std::chrono::milliseconds timeout = std::chrono::seconds(60));
  nlohmann::json cli_json(std::vector<std::string> args);

  const std::string& url() const { return url_; }
  TempDir dir;
  nlohmann::json announcement;

 private:
  std::unique_ptr<Process> sim_;
  std::unique_ptr<Process> daemon_;
  std::string url_;
  std::string unix_socket_;
};

}  // namespace colorlab::testing
