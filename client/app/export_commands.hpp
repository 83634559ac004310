#pragma once
// `colorlab export RUN --format ti3|csv|json [-o FILE]`: a run's measurements as a file.
#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace colorlab::cli {

void add_export_command(CLI::App& app, GlobalOptions& global);

}  // namespace colorlab::cli
