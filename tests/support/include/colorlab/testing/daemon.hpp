#pragma once
// colorlabd as a real process for integration tests: started on a state directory (and a
// configuration file, if any) with port 0, found through the endpoint file it writes once it
// serves, killed with SIGKILL or stopped with SIGTERM, and started again on the same state.
#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/testing/process.hpp"

namespace colorlab::testing {

// Waits until <state_dir>/colorlabd.endpoint names process `pid` (a file left by a killed
// predecessor names another pid) and returns its JSON; throws std::runtime_error on timeout.
nlohmann::json wait_for_endpoint(const std::filesystem::path& state_dir, pid_t pid,
                                 std::chrono::milliseconds timeout = std::chrono::seconds(20));

class DaemonProcess {
 public:
  // `config`: a TOML file for --config; without it colorlabd starts its embedded simulated lab.
  explicit DaemonProcess(std::filesystem::path state_dir, std::optional<std::filesystem::path> config = std::nullopt,
                         std::filesystem::path log = {});
  // Kills the daemon and waits for its embedded simulated lab to go too (it holds the GigE
  // Vision port on 127.0.0.1 a moment longer than its parent lives).
  ~DaemonProcess();
  void start();
  void kill9();     // no cleanup: the embedded simulated lab dies with it (waited for)
  int terminate();  // SIGTERM and wait; returns the exit code
  bool running();
  const std::string& url() const { return url_; }
  // The Unix socket has every scope (docs/API.md, "Access"): tests that drive the lab use it; loopback
  // TCP without a key only reads.
  const std::string& unix_socket() const { return unix_socket_; }
  Process& process() { return *process_; }
  const std::filesystem::path& state_dir() const { return state_dir_; }

 private:
  std::filesystem::path state_dir_;
  std::optional<std::filesystem::path> config_;
  std::filesystem::path log_;
  void wait_for_simulator_exit();

  std::unique_ptr<Process> process_;
  std::string url_;
  std::string unix_socket_;
  pid_t simulator_pid_ = -1;
};

}  // namespace colorlab::testing
