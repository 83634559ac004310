#pragma once
// `colorlab locate-chart --blob SHA256 [--chart sg|cc24] [--corners x1,y1,…,x4,y4] [--json]`: the chart located in a
// photograph the daemon keeps (POST /v1/blobs/{sha256}/locate-chart), automatically or from the operator's corners.
// `colorlab analyze locate-chart PHOTO` does the same to a local file without a daemon.
#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace colorlab::cli {

void add_locate_commands(CLI::App& app, GlobalOptions& global);

}  // namespace colorlab::cli
