// colorlab-sim: the simulated colour lab. Prints one JSON line describing every endpoint, then
// serves until SIGTERM/SIGINT. See docs/simulator.md.
#include <unistd.h>

#include <cstdlib>
#include <iostream>

#include <boost/asio/io_context.hpp>
#include <boost/asio/signal_set.hpp>
#include <CLI/CLI.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/core/log.hpp"
#include "colorlab/sim/capture_scratch.hpp"
#include "colorlab/sim/control_channel.hpp"
#include "colorlab/sim/lab.hpp"

namespace {

std::filesystem::path default_control_path() {
  const char* runtime = std::getenv("XDG_RUNTIME_DIR");
  std::filesystem::path dir = runtime && *runtime ? runtime : std::filesystem::temp_directory_path();
  return dir / ("colorlab-sim-" + std::to_string(::getpid()) + ".sock");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"colorlab-sim — the simulated colour lab: instruments on pseudo-terminals speaking their real protocols"};
  std::string config_file;
  double time_scale = 0;
  long long seed = -1;
  std::string control;
  std::string scratch;
  std::string genicam_address;
  app.add_option("--config", config_file, "lab configuration (TOML); default: every instrument")->check(CLI::ExistingFile);
  app.add_option("--time-scale", time_scale, "simulated seconds per real second (overrides the config)");
  app.add_option("--seed", seed, "random seed (overrides the config)");
  app.add_option("--control", control, "control socket path");
  app.add_option("--scratch-dir", scratch, "where the DSLR's card folder goes when [dslr] capture_dir is not set (default: the temporary directory)");
  app.add_option("--genicam-address", genicam_address,
                 "the GigE Vision camera's IPv4 address (overrides [genicam] address; default 127.0.0.1): one fake "
                 "per address, so each lab on one machine needs its own, held by an interface (docs/simulator.md)");
  CLI11_PARSE(app, argc, argv);

  try {
    auto config = config_file.empty() ? colorlab::sim::LabConfig{} : colorlab::sim::load_lab_config(config_file);
    if (time_scale > 0) config.time_scale = time_scale;
    if (seed >= 0) config.seed = static_cast<std::uint64_t>(seed);
    if (!control.empty()) config.control_socket = control;
    if (!scratch.empty()) config.scratch_dir = scratch;
    if (!genicam_address.empty()) config.genicam.address = genicam_address;

    // A simulator killed with SIGKILL leaves its default sockets behind; the next one removes them.
    colorlab::sim::reclaim_dead_sockets(default_control_path().parent_path());
    boost::asio::io_context io{1};
    colorlab::sim::Lab lab(io, config);
    colorlab::sim::ControlChannel channel(io, config.control_socket.value_or(default_control_path()),
                                          [&lab](const nlohmann::json& cmd) { return lab.control(cmd); });
    auto announcement = lab.announcement();
    announcement["control"] = channel.path().string();
    std::cout << announcement.dump() << std::endl;

    boost::asio::signal_set signals(io, SIGINT, SIGTERM);
    signals.async_wait([&io](boost::system::error_code, int) { io.stop(); });
    io.run();
    return 0;
  } catch (const colorlab::Error& e) {
    std::cerr << "colorlab-sim: " << e.what() << "\n";
    if (!e.hint().empty()) std::cerr << "  hint: " << e.hint() << "\n";
    return 1;
  }
}
