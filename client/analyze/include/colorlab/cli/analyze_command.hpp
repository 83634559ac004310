#pragma once
// `colorlab analyze ...`: colour science over files (CGATS/CSV in, CSV or --json out).
#include <CLI/CLI.hpp>

namespace colorlab::cli {

// Adds the `analyze` subcommand tree (xyz, lab, de2000, fit, uniformity, averaging, locate-chart, stability) to the application.
// Results go to stdout; errors are thrown as colorlab::Error from the callbacks.
void add_analyze_command(CLI::App& app);

}  // namespace colorlab::cli
