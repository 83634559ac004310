#pragma once
// `colorlab queue …`: the night's queue (add, list, remove, move, start, stop).
#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace colorlab::cli {

void add_queue_commands(CLI::App& app, GlobalOptions& global);

}  // namespace colorlab::cli
