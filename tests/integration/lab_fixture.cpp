#include "lab_fixture.hpp"

#include "colorlab/testing/daemon.hpp"

#include <fstream>
#include <thread>

#include <gtest/gtest.h>

#include "colorlab/sim/control_channel.hpp"

namespace colorlab::testing {

using nlohmann::json;

std::string write_sim_config_without_camera(const std::filesystem::path& dir) {
  auto path = dir / "lab.toml";
  // The GigE Vision fake can serve 127.0.0.1 only once; tests without a camera leave it to those with one.
  std::ofstream(path) << "[genicam]\nenabled = false\n";
  return path.string();
}

LabFixture::LabFixture(double time_scale, std::string ls110_options) {
  sim_ = std::make_unique<Process>(
      std::vector<std::string>{bin_path("colorlab-sim"), "--config", write_sim_config_without_camera(dir.path()),
                               "--seed", "7", "--time-scale", std::to_string(time_scale), "--control",
                               (dir / "sim.sock").string()},
      dir / "sim.log");
  auto line = sim_->read_line(std::chrono::seconds(20));
  if (!line) throw std::runtime_error("colorlab-sim did not announce itself");
  announcement = json::parse(*line);
  std::string port;
  for (const auto& i : announcement["instruments"]) {
    if (i["kind"] == "ls110") port = i["port"];
  }
  if (port.empty()) throw std::runtime_error("colorlab-sim announced no LS-110");
  std::ofstream(dir / "colorlabd.toml") << "state_dir = \"state\"\nlisten = \"127.0.0.1:0\"\n\n"
                                        << "[[instrument]]\nid = \"ls110\"\nkind = \"ls110\"\nport = \"" << port
                                        << "\"\nsimulated = true\noptions = " << ls110_options << "\n";
  start_daemon();
}

LabFixture::~LabFixture() = default;

void LabFixture::start_daemon() {
  daemon_ = std::make_unique<Process>(
      std::vector<std::string>{bin_path("colorlabd"), "--config", (dir / "colorlabd.toml").string()},
      dir / "colorlabd.log");
  auto endpoint = wait_for_endpoint(dir / "state", daemon_->pid());
  url_ = endpoint["url"];
  unix_socket_ = endpoint["unix_socket"];
}

void LabFixture::kill_daemon() {
  daemon_->signal(SIGKILL);
  daemon_->wait(std::chrono::seconds(10));
}

json LabFixture::sim_control(const json& command) {
  return colorlab::sim::send_control_command(dir / "sim.sock", command);
}

RunResult LabFixture::cli(std::vector<std::string> args, std::chrono::milliseconds timeout) {
  std::vector<std::string> argv{bin_path("colorlab"), "--socket", unix_socket_};
  argv.insert(argv.end(), args.begin(), args.end());
  return run_command(argv, timeout);
}

json LabFixture::cli_json(std::vector<std::string> args) {
  args.insert(args.begin(), "--json");
  auto r = cli(args);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return json::parse(r.out);
}

}  // namespace colorlab::testing
