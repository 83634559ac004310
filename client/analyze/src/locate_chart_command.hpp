#pragma once
// `colorlab analyze locate-chart PHOTO --chart sg|cc24 [--corners x1,y1,…] [--json]`.
#include <CLI/CLI.hpp>

namespace colorlab::cli::detail {

void add_locate_chart_command(CLI::App& analyze);

}  // namespace colorlab::cli::detail
