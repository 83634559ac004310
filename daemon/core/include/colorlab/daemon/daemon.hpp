#pragma once
// colorlabd assembled: store, instruments, campaigns, executions, HTTP server, systemd.
// Everything runs on one io_context thread; SQLite and the drivers are used from it only.
#include <memory>
#include <string>

#include "colorlab/daemon/config.hpp"

namespace colorlab::daemon {

class Daemon {
 public:
  explicit Daemon(DaemonConfig config);
  ~Daemon();
  // Runs until SIGINT/SIGTERM. Returns the process exit code.
  int run();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace colorlab::daemon
