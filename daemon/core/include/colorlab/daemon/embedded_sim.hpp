#pragma once
// Runs colorlab-sim as a child process for the embedded default configuration: the daemon then
// talks to the simulated instruments over their ptys with the same drivers as to real ones.
// The child dies with the daemon (PR_SET_PDEATHSIG), even after kill -9.
#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/campaigns/instrument_set.hpp"
#include "colorlab/daemon/config.hpp"

namespace colorlab::daemon {

class EmbeddedSim {
 public:
  // Starts the simulator and waits for its one-line JSON announcement. Throws Error{no_comms}.
  // `scratch_dir` (colorlabd: <state_dir>/sim) holds the simulated DSLR's card folder, so a simulator
  // killed with the daemon leaves it in the state directory, where the next one reclaims it.
  EmbeddedSim(const std::filesystem::path& sim_binary, const SimulatorConfig& config, const std::filesystem::path& scratch_dir,
              std::chrono::milliseconds startup_timeout = std::chrono::seconds(20));
  ~EmbeddedSim();
  EmbeddedSim(const EmbeddedSim&) = delete;
  EmbeddedSim& operator=(const EmbeddedSim&) = delete;

  const nlohmann::json& announcement() const { return announcement_; }
  // The announced serial instruments as driver configurations (simulated = true).
  std::vector<drivers::InstrumentConfig> instruments() const;
  // The instruments the simulated lab was asked for but could not start (its announcement's "absent").
  std::vector<campaigns::AbsentInstrument> absent_instruments() const;
  pid_t pid() const { return pid_; }

 private:
  pid_t pid_ = -1;
  int stdout_fd_ = -1;
  nlohmann::json announcement_;
};

// $COLORLAB_SIM, else colorlab-sim next to the running executable, else in ../bin (installed: sbin/colorlabd).
std::filesystem::path default_sim_binary();

}  // namespace colorlab::daemon
