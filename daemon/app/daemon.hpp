#pragma once
// colorlabd assembled: store, instruments, campaigns, executions, the night's queue, HTTP server, systemd.
// Live state (instruments, executions, the queue, the writer connection) lives on the main io_context
// thread; stored data is read on the HTTP pool's threads (the route table places each route).
#include <memory>
#include <string>

#include "colorlab/daemon/config.hpp"

namespace colorlab::daemon {

// <state_dir>/colorlabd.endpoint: {"pid","url","port","unix_socket"} of the running daemon.
std::filesystem::path endpoint_file_path(const DaemonConfig& config);

class Daemon {
 public:
  explicit Daemon(DaemonConfig config);
  ~Daemon();
  // Runs until SIGINT/SIGTERM. Returns the process exit code.
  int run();

 private:
  void write_endpoint_file();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace colorlab::daemon
