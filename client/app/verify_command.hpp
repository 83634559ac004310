#pragma once
// `colorlab verify RENDERING --against RUN… [--json] [--scale X] [--no-rendering-noise] [--noise-neighbours N] [--store]`: a renderer's image beside the measured
// scene, with the measurement's own uncertainty (issue 23, docs/verify.md "Using it"). The rendering is read here;
// the runs come from the daemon; the verdict is the exit status (0 agrees, 4 differs; 1 local error, 2 API refused).
#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace colorlab::cli {

void add_verify_command(CLI::App& app, GlobalOptions& global);

}  // namespace colorlab::cli
