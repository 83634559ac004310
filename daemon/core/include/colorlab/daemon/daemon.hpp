#pragma once
// colorlabd assembled: store, instruments, campaigns, executions, the night's queue, HTTP server, systemd.
// Everything runs on one io_context thread; SQLite and the drivers are used from it only.
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
