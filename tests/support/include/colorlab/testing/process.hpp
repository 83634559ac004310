#pragma once
// A child process for integration tests: started with argv, stdout captured line by line,
// stderr to a log file, killed (SIGKILL) when the object dies so a failing test leaves nothing.
#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace colorlab::testing {

class Process {
 public:
  Process(std::vector<std::string> argv, std::filesystem::path stderr_log = "/dev/null",
          std::optional<std::filesystem::path> working_dir = std::nullopt);
  ~Process();
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

  pid_t pid() const { return pid_; }
  // Next line of stdout, or nullopt on EOF/timeout.
  std::optional<std::string> read_line(std::chrono::milliseconds timeout);
  void signal(int sig);
  // Waits for exit; returns the exit code (128 + signal when killed), nullopt on timeout.
  std::optional<int> wait(std::chrono::milliseconds timeout);
  bool running();

 private:
  pid_t pid_ = -1;
  int stdout_fd_ = -1;
  std::string buffer_;
  std::optional<int> exit_code_;
};

struct RunResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};
// Runs a command to completion (with a timeout) and captures its output.
RunResult run_command(const std::vector<std::string>& argv, std::chrono::milliseconds timeout = std::chrono::seconds(60));

std::string bin_path(const std::string& name);  // COLORLAB_BIN_DIR/name

// Whether an external tool (argyll, dcraw, unshare, ...) is installed, for skip-with-a-reason checks.
bool on_path(const std::string& tool);
// A shell command's standard output (empty if it could not start); its exit status is not reported.
std::string shell_output(const std::string& command);

}  // namespace colorlab::testing
