#pragma once
// CPU priority of colorlabd's heavy threads (issue 27): fits, analyses, RAW decoding, report
// generation and the blob check run `heavy_nice` nice steps below the threads that answer (the io
// thread and the HTTP pool), so that on a 2-core lab PC an answer never waits a scheduler slice
// behind a fit. Nice rather than SCHED_IDLE: an idle-class thread gets nothing while anything else
// wants the CPU (a build at nice 19, a virus scan), which could stall a night's fit indefinitely;
// nice 10 still gets about a tenth of a contended CPU and all of an idle one.
//
// Linux keeps a nice value per thread and a new thread or child process inherits its creator's, so
// a heavy thread lowers itself once when it starts and whatever it spawns (the report's Python
// client) follows. Raising a thread back needs CAP_SYS_NICE: lowering is one-way on purpose.
#include <filesystem>
#include <string_view>

namespace colorlab::core {

// The process-wide amount heavy threads lower themselves by (0..19; 0 = as the daemon, main's
// behaviour before issue 27). Set once at start-up, before the heavy threads exist.
void set_heavy_thread_nice(int steps);
int heavy_thread_nice();

// Lowers the calling thread to `steps` nice steps below the process's own nice value (clamped at 19), or leaves it
// where it is if it is already that low (a heavy thread started by a heavy thread); a failure is logged with `who`
// and otherwise ignored (the thread still works, only unprioritised).
void lower_this_thread(int steps, std::string_view who);

// The first call of a heavy thread: names it (`name`, 15 characters at most: top -H, /proc/…/comm, the latency
// probe's per-thread figures) and lowers it by heavy_thread_nice().
void become_heavy_thread(std::string_view name);

// A thread's nice value as the kernel reports it (/proc/self/task/TID/stat, field 19); the calling
// thread when tid is 0. Throws colorlab::Error when it cannot be read.
int thread_nice(long tid = 0);
// The nice value in a /proc stat file (/proc/PID/stat, /proc/self/task/TID/stat). Throws colorlab::Error.
int nice_in_stat(const std::filesystem::path& stat_file);

}  // namespace colorlab::core
