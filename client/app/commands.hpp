#pragma once
// The daemon-facing subcommands of `colorlab`.
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace colorlab::cli {

struct GlobalOptions {
  std::string url = "http://127.0.0.1:8765";
  std::string socket;
  bool json = false;
  std::string key;     // API key, sent as Authorization: Bearer
  std::string cacert;  // PEM CA file for https:// (default: the system's store)
};

void add_daemon_commands(CLI::App& app, GlobalOptions& global);

}  // namespace colorlab::cli
