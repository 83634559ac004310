#pragma once
// `colorlab lens calibrate PHOTO…` and `colorlab lens list`: the lab's lens calibrations (docs/verify.md, "The
// lens calibration"), obtained from chart photographs and kept as [[lens]] tables in the lab configuration.
#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace colorlab::cli {

void add_lens_commands(CLI::App& app, GlobalOptions& global);

}  // namespace colorlab::cli
