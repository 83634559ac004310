#pragma once
// `colorlab analyze stability --train CHART [--test CHART] [--other-lamp LAMP=CHART]… [--methods …] [--json]`:
// the analysis library's stability suite (analysis/stability.hpp) over chart files.
#include <CLI/CLI.hpp>

namespace colorlab::cli::detail {

void add_stability_command(CLI::App& analyze);

}  // namespace colorlab::cli::detail
