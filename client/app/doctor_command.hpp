#pragma once
// `colorlab doctor`: the first night on real hardware (docs/bring-up.md). Lists the host's serial,
// USB and GigE devices with their udev identities, permissions, groups and colorlab's udev rules;
// identifies the instrument on each serial port by its protocol's own handshake; shows calibration
// state; and only with the operator's agreement (--measure, --yes or the prompt) takes one reading
// from each, asking the operator to confirm it against the instrument. Every byte exchanged is
// written as a transcript that tests/transcripts replays. Runs without a daemon.
#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace colorlab::cli {

void add_doctor_command(CLI::App& app, GlobalOptions& global);

}  // namespace colorlab::cli
