#include "backup_commands.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "colorlab/core/error.hpp"

namespace colorlab::cli {

namespace fs = std::filesystem;

namespace {

struct BackupOptions {
  std::string config = "/etc/colorlab/colorlabd.toml";
  std::string snapshot;
  std::string into;
};

// colorlab-ship installed beside this binary (a build tree or /usr/bin), else from PATH.
[[noreturn]] void exec_ship(const std::vector<std::string>& ship_args) {
  std::string ship = "colorlab-ship";
  std::error_code ec;
  if (const auto self = fs::read_symlink("/proc/self/exe", ec); !ec && fs::exists(self.parent_path() / ship)) {
    ship = (self.parent_path() / ship).string();
  }
  std::vector<std::string> args{ship};
  args.insert(args.end(), ship_args.begin(), ship_args.end());
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  ::execvp(ship.c_str(), argv.data());
  throw Error(ErrorClass::not_found, "cannot run " + ship + ": " + std::strerror(errno),
              "backups go through colorlab-ship, built and installed with colorlab (docs/fleet.md)");
}

}  // namespace

void add_backup_commands(CLI::App& app) {
  auto o = std::make_shared<BackupOptions>();
  auto* backup = app.add_subcommand(
      "backup",
      "Snapshot this bench's store (consistent while campaigns write) with the blobs it references into the "
      "lab's bucket, then apply the rotation policy; prints a JSON report (docs/fleet.md, Backups)");
  backup->add_option("--config", o->config, "colorlabd's TOML with its [ship] section")->capture_default_str();
  backup->callback([o] { exec_ship({"--config", o->config, "backup"}); });

  auto* restore = app.add_subcommand(
      "restore",
      "Rebuild a state directory (database and blobs) from the newest or a named snapshot, in a new restore "
      "epoch so shipping resumes; start colorlabd on it afterwards (docs/fleet.md, Backups)");
  restore->add_option("--config", o->config, "colorlabd's TOML with its [ship] section")->capture_default_str();
  restore->add_option("--snapshot", o->snapshot, "the snapshot's name (default: the newest)");
  restore->add_option("--into", o->into, "the directory to rebuild (default: the TOML's state_dir; no database in it)");
  restore->callback([o] {
    std::vector<std::string> args{"--config", o->config, "restore"};
    if (!o->snapshot.empty()) args.insert(args.end(), {"--snapshot", o->snapshot});
    if (!o->into.empty()) args.insert(args.end(), {"--into", o->into});
    exec_ship(args);
  });
}

}  // namespace colorlab::cli
