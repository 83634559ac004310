#pragma once
// The embedded simulated lab's DSLR capture folder (/tmp/colorlab-sim-<pid>-dslr) outlives the daemon, which kills
// its simulator without letting it clean up; the machine's /tmp is shared, and full-size frames add up. Declared
// before the DaemonProcess, so the daemon and its simulator are gone first; removed however the test ends.
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include <nlohmann/json.hpp>

#include "colorlab/testing/daemon.hpp"

namespace colorlab::testing {

struct SimulatorCaptureFolder {
  std::filesystem::path path;
  void note(const DaemonProcess& daemon) {
    const auto endpoint = nlohmann::json::parse(std::ifstream(daemon.state_dir() / "colorlabd.endpoint"));
    if (endpoint.contains("simulator_pid"))
      path = std::filesystem::temp_directory_path() /
             ("colorlab-sim-" + std::to_string(endpoint["simulator_pid"].get<long>()) + "-dslr");
  }
  SimulatorCaptureFolder() = default;
  SimulatorCaptureFolder(const SimulatorCaptureFolder&) = delete;
  SimulatorCaptureFolder& operator=(const SimulatorCaptureFolder&) = delete;
  ~SimulatorCaptureFolder() {
    std::error_code ignored;
    if (!path.empty()) std::filesystem::remove_all(path, ignored);
  }
};

}  // namespace colorlab::testing
