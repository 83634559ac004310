#include "colorlab/testing/daemon.hpp"

#include <signal.h>

#include <fstream>
#include <stdexcept>
#include <thread>

namespace colorlab::testing {

nlohmann::json wait_for_endpoint(const std::filesystem::path& state_dir, pid_t pid, std::chrono::milliseconds timeout) {
  auto file = state_dir / "colorlabd.endpoint";
  auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    std::ifstream in(file);
    if (in) {
      auto j = nlohmann::json::parse(in, nullptr, false);
      if (!j.is_discarded() && j.value("pid", -1) == pid) return j;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  throw std::runtime_error("colorlabd (pid " + std::to_string(pid) + ") did not write " + file.string() + " in time");
}

DaemonProcess::DaemonProcess(std::filesystem::path state_dir, std::optional<std::filesystem::path> config,
                             std::filesystem::path log)
    : state_dir_(std::move(state_dir)), config_(std::move(config)), log_(std::move(log)) {
  if (log_.empty()) log_ = state_dir_.parent_path() / (state_dir_.filename().string() + ".colorlabd.log");
  start();
}

void DaemonProcess::start() {
  std::vector<std::string> argv{bin_path("colorlabd"), "--state", state_dir_.string(), "--listen", "127.0.0.1:0"};
  if (config_) {
    argv.push_back("--config");
    argv.push_back(config_->string());
  }
  process_.reset();
  // Append, so a restarted daemon's log follows the killed one's.
  process_ = std::make_unique<Process>(argv, log_);
  auto endpoint = wait_for_endpoint(state_dir_, process_->pid());
  url_ = endpoint["url"];
  unix_socket_ = endpoint["unix_socket"];
  simulator_pid_ = endpoint.value("simulator_pid", -1);
}

DaemonProcess::~DaemonProcess() {
  if (process_ && process_->running()) kill9();
  wait_for_simulator_exit();
}

void DaemonProcess::wait_for_simulator_exit() {
  if (simulator_pid_ <= 0) return;
  for (int i = 0; i < 500 && ::kill(simulator_pid_, 0) == 0; ++i) {
    // A zombie (not yet reaped by init) no longer holds anything.
    std::ifstream stat("/proc/" + std::to_string(simulator_pid_) + "/stat");
    std::string pid, comm, state;
    if (stat >> pid >> comm >> state && state == "Z") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  simulator_pid_ = -1;
}

void DaemonProcess::kill9() {
  process_->signal(SIGKILL);
  process_->wait(std::chrono::seconds(10));
  wait_for_simulator_exit();
}

int DaemonProcess::terminate() {
  process_->signal(SIGTERM);
  int code = process_->wait(std::chrono::seconds(30)).value_or(-1);
  wait_for_simulator_exit();
  return code;
}

bool DaemonProcess::running() { return process_ && process_->running(); }

}  // namespace colorlab::testing
