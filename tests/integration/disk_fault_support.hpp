#pragma once
// colorlabd under a preloaded library, without privileges: the fault shim (tests/support/faultshim) makes
// its state directory's disk full (ENOSPC) or failing (EIO) and mends it again while it runs; sockets and
// every other file are untouched, so the API, the simulated lab and the test go on as before.
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

#include "colorlab/testing/daemon.hpp"
#include "scoped_env.hpp"

namespace colorlab::testing {

class DiskFaults {
 public:
  // `state_dir` is created here: the shim resolves it once, when the daemon first writes.
  DiskFaults(std::filesystem::path state_dir, std::filesystem::path control)
      : state_dir_(std::move(state_dir)), control_(std::move(control)) {
    std::filesystem::create_directories(state_dir_);
  }
  // "ENOSPC" or "EIO", optionally followed by a subdirectory of the state directory ("ENOSPC blobs").
  void fail(const std::string& how) {
    const auto tmp = control_.string() + ".tmp";
    std::ofstream(tmp) << how << "\n";
    std::filesystem::rename(tmp, control_);  // whole at once: the shim never reads half a line
  }
  void mend() { std::filesystem::remove(control_); }

  // colorlabd (and what it starts: the embedded lab, the report module) with the shim preloaded.
  std::unique_ptr<DaemonProcess> start(const std::optional<std::filesystem::path>& config) const {
    ScopedEnv env{{"LD_PRELOAD", COLORLAB_FAULTSHIM},
                  {"COLORLAB_FAULT_DIR", state_dir_.string()},
                  {"COLORLAB_FAULT_CONTROL", control_.string()},
                  {"ASAN_OPTIONS", asan_options_for_preload()},
                  {"TSAN_OPTIONS", tsan_options_for_preload()}};
    return std::make_unique<DaemonProcess>(state_dir_, config);
  }

  const std::filesystem::path& state_dir() const { return state_dir_; }

 private:
  std::filesystem::path state_dir_;
  std::filesystem::path control_;
};

}  // namespace colorlab::testing
