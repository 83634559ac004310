#pragma once
// colorlab-sim as a process for the driver tests of its socket instruments: started on a lab TOML
// in a fresh directory, its announcement read, its control channel at hand, an announced entry
// turned into the InstrumentConfig the daemon would build from it.
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "colorlab/drivers/factory.hpp"
#include "colorlab/sim/control_channel.hpp"
#include "colorlab/testing/process.hpp"
#include "colorlab/testing/temp_dir.hpp"

namespace colorlab::testing {

class SimLabProcess {
 public:
  // `lab_toml` is written to lab.toml; the GigE Vision camera is left off (it needs the loopback lock).
  explicit SimLabProcess(const std::string& lab_toml, double time_scale = 1000, int seed = 5) {
    const auto config = dir / "lab.toml";
    std::ofstream(config) << "[genicam]\nenabled = false\n"
                          << lab_toml;
    process = std::make_unique<Process>(
        std::vector<std::string>{bin_path("colorlab-sim"), "--config", config.string(), "--seed", std::to_string(seed),
                                 "--time-scale", std::to_string(time_scale), "--control", (dir / "sim.sock").string()},
        dir / "sim.log");
    auto line = process->read_line(std::chrono::seconds(20));
    if (!line) throw std::runtime_error("colorlab-sim did not announce itself (see its log)");
    announcement = nlohmann::json::parse(*line);
  }

  nlohmann::json control(const nlohmann::json& command) { return sim::send_control_command(dir / "sim.sock", command); }

  // The announced entry of `kind`, as colorlabd's embedded lab turns it into a configuration.
  drivers::InstrumentConfig config_for(const std::string& kind) const {
    for (const auto& i : announcement["instruments"]) {
      if (i["kind"] != kind) continue;
      drivers::InstrumentConfig c;
      c.id = i["id"];
      c.kind = kind;
      c.port = i.value("port", std::string());
      c.simulated = true;
      if (i.contains("driver_options")) c.options = i["driver_options"];
      return c;
    }
    throw std::runtime_error("colorlab-sim announced no " + kind + ": " + announcement.dump());
  }

  TempDir dir;
  std::unique_ptr<Process> process;
  nlohmann::json announcement;
};

}  // namespace colorlab::testing
