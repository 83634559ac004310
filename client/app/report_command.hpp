#pragma once
// `colorlab report RUN… [-o FILE]`: the dissertation's tables and figures from stored runs, as one
// self-contained HTML file, made by the Python client's report package (matplotlib); and `colorlab study
// dissertation`: the whole study through the night queue, then its report (the Python client's study package).
#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace colorlab::cli {

void add_report_command(CLI::App& app, GlobalOptions& global);

}  // namespace colorlab::cli
