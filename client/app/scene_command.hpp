#pragma once
// `colorlab scene RUN… -o DIR`: the measured scene exported for a renderer (scene.json + build_scene.py for
// Blender; docs/verify.md, "The measured scene").
#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace colorlab::cli {

void add_scene_command(CLI::App& app, GlobalOptions& global);

}  // namespace colorlab::cli
