#pragma once
// `colorlab blobs RUN` (the frames a run kept) and `colorlab download SHA256 [-o FILE|DIR]` (one of them,
// byte for byte, as the image store holds it).
#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace colorlab::cli {

void add_blob_commands(CLI::App& app, GlobalOptions& global);

}  // namespace colorlab::cli
