#pragma once
// `colorlab keys …` (API keys: create, list, revoke) and `colorlab control …` (the control lock:
// acquire, release, status).
#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace colorlab::cli {

void add_access_commands(CLI::App& app, GlobalOptions& global);

}  // namespace colorlab::cli
