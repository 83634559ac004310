#pragma once
// colorlabd under the fault shim (tests/support/faultshim): its state directory's disk made full (ENOSPC)
// or failing (EIO) and mended again while it runs, without privileges. Sockets and every other file
// are untouched, so the API, the simulated lab and the test go on as before.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

#include "colorlab/testing/daemon.hpp"

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
    Env env{{"LD_PRELOAD", COLORLAB_FAULTSHIM},
            {"COLORLAB_FAULT_DIR", state_dir_.string()},
            {"COLORLAB_FAULT_CONTROL", control_.string()},
            // Under the asan preset the shim precedes ASan's runtime, which ASan's start-up check refuses.
            {"ASAN_OPTIONS", std::string(std::getenv("ASAN_OPTIONS") ? std::getenv("ASAN_OPTIONS") : "") +
                                 ":verify_asan_link_order=0"}};
    return std::make_unique<DaemonProcess>(state_dir_, config);
  }

  const std::filesystem::path& state_dir() const { return state_dir_; }

 private:
  // Set for the child's start only: the test process itself must not inherit the shim's variables.
  struct Env {
    Env(std::initializer_list<std::pair<const char*, std::string>> vars) {
      for (const auto& [name, value] : vars) {
        const char* old = std::getenv(name);
        saved.emplace_back(name, old ? std::optional<std::string>(old) : std::nullopt);
        ::setenv(name, value.c_str(), 1);
      }
    }
    ~Env() {
      for (const auto& [name, value] : saved) {
        if (value) ::setenv(name, value->c_str(), 1);
        else ::unsetenv(name);
      }
    }
    std::vector<std::pair<const char*, std::optional<std::string>>> saved;
  };

  std::filesystem::path state_dir_;
  std::filesystem::path control_;
};

}  // namespace colorlab::testing
