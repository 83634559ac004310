#pragma once
// `colorlab backup` and `colorlab restore` (docs/fleet.md, "Backups"): they run `colorlab-ship backup|restore`,
// which holds the bucket's client and credentials (the [ship] section), so this client links no S3 or
// PostgreSQL code and a bench without shipping set up gets colorlab-ship's own message.
#include <CLI/CLI.hpp>

namespace colorlab::cli {

void add_backup_commands(CLI::App& app);

}  // namespace colorlab::cli
