#pragma once
// The simulated DSLR's default card folder, <root>/colorlab-sim-<pid>-dslr, and the reclaiming of the
// folders that killed simulators left behind. A colorlab-sim that exits removes its own folder; one
// killed with SIGKILL cannot (issue 27: 10–20 MB a test, gigabytes a soak night), so the next
// simulator started on the same root removes the folders whose process no longer runs. Several
// simulators share a root in the tests, so a folder whose pid still runs is never touched.
#include <sys/types.h>

#include <filesystem>
#include <vector>

namespace colorlab::sim {

std::filesystem::path default_capture_dir(const std::filesystem::path& root, pid_t pid);

// Whether `pid` no longer runs: no such process, or a zombie waiting to be reaped. A pid that runs
// another program now (reuse) counts as running: its folder is kept, never wrongly deleted.
bool process_is_gone(pid_t pid);

// Removes every <root>/colorlab-sim-<pid>-dslr directory whose pid is gone; returns those removed.
// Errors (a folder of another user, a vanished root) leave the folder and are not thrown.
std::vector<std::filesystem::path> reclaim_dead_capture_dirs(const std::filesystem::path& root);

// The same for the sockets a simulator makes when none is configured: <dir>/colorlab-sim-<pid>.sock (control)
// and <dir>/colorlab-sim-<pid>-<name>.sock (dslr, relay), $XDG_RUNTIME_DIR or the temporary directory.
// Only sockets are removed.
std::vector<std::filesystem::path> reclaim_dead_sockets(const std::filesystem::path& dir);

}  // namespace colorlab::sim
