#include "report_command.hpp"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>

#include "client_support.hpp"
#include "colorlab/core/data_paths.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::cli {

namespace fs = std::filesystem;

namespace {

struct ReportOptions {
  std::vector<std::string> runs;
  std::string output;
};

struct StudyOptions {
  std::string study;
  std::string output;
  std::vector<std::string> overrides;
  std::string state_file;
  bool dry_run = false, small = false, resume = false;
};

// Replaces this process with a module of the Python client (the report, a study), so its output, progress
// and exit code are the command's own.
[[noreturn]] void exec_module(const GlobalOptions& g, const std::string& module, const std::vector<std::string>& module_args) {
  const char* python = std::getenv("COLORLAB_PYTHON");
  const std::string interpreter = python && *python ? python : "/usr/bin/python3";
  std::vector<std::string> args{interpreter, "-m", module};
  args.insert(args.end(), module_args.begin(), module_args.end());
  if (!g.socket.empty()) {
    args.insert(args.end(), {"--socket", g.socket});
  } else {
    args.insert(args.end(), {"--url", g.url});
  }
  // The key goes by environment, not argv, where any user's `ps` would see it.
  if (!g.key.empty()) ::setenv("COLORLAB_API_KEY", g.key.c_str(), 1);
  if (!g.cacert.empty()) ::setenv("REQUESTS_CA_BUNDLE", g.cacert.c_str(), 1);
  // The report runs `colorlab analyze` (the stability suite): this very binary.
  std::error_code ec;
  if (const auto self = fs::read_symlink("/proc/self/exe", ec); !ec) ::setenv("COLORLAB_BIN", self.c_str(), 0);
  if (auto path = paths::python_client_dir().string(); !path.empty()) {
    const char* existing = std::getenv("PYTHONPATH");
    const std::string joined = existing && *existing ? path + ":" + existing : path;
    ::setenv("PYTHONPATH", joined.c_str(), 1);
  }
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  ::execv(interpreter.c_str(), argv.data());
  throw Error(ErrorClass::not_found, "cannot run " + interpreter + ": " + std::strerror(errno),
              "reports and studies need Python 3 with matplotlib, numpy, pandas and requests: scripts/setup.sh installs them");
}

}  // namespace

void add_report_command(CLI::App& app, GlobalOptions& global) {
  auto o = std::make_shared<ReportOptions>();
  auto* cmd = app.add_subcommand(
      "report",
      "Write the dissertation's tables and figures for stored runs (frame-average, cabinet-grid, floor-luminance, "
      "chart-read, characterize-camera, dimmer-exposure, luminance-spot) as one self-contained HTML file, each beside "
      "the published numbers; "
      "prints its path (with --json before the command: one JSON object with the path, the runs and the timings)");
  cmd->add_option("runs", o->runs, "run ids (colorlab runs lists them)")->required();
  cmd->add_option("-o,--output", o->output, "HTML file to write (default: ./report-<first run>.html)");
  cmd->callback([&global, o] {
    for (const auto& run : o->runs) check_id(run, "a run id", "colorlab runs lists them");
    std::vector<std::string> args = o->runs;
    if (!o->output.empty()) args.insert(args.end(), {"-o", o->output});
    if (global.json) args.push_back("--json");
    // 0 written, 2 usage, 3 a run not found or the daemon unreachable.
    exec_module(global, "colorlab.report", args);
  });

  auto s = std::make_shared<StudyOptions>();
  auto* study = app.add_subcommand(
      "study",
      "Run a study — a sequence of the daemon's catalogue, e.g. dissertation: the SG chart read, 25-frame averaging, "
      "the cabinet grid over lamps and dimmer levels, the camera as a luminance meter, camera characterization, "
      "dimmer exposure — queued as one group of the night queue, followed live, then write its report; prints its path "
      "(with --json before the command: progress on stderr, then one JSON object with the runs, the report and the timings)");
  // Which studies exist is the daemon's catalogue's to say (the module refuses an unknown one with exit 2, naming
  // the sequences there), so a lab's own NAME.sequence.lua runs too.
  study->add_option("study", s->study, "the study: a sequence (colorlab campaigns lists them), e.g. dissertation")->required();
  study->add_option("-o,--output", s->output, "the report's HTML file (default: ./report-<first run>.html)");
  study->add_option("--set", s->overrides, "override one step's parameter, STEP.KEY=VALUE (repeatable), e.g. cabinet-grid.rows=4");
  study->add_flag("--dry-run", s->dry_run, "each campaign's dry run and the estimated total; nothing is queued");
  study->add_flag("--small", s->small, "a reduced study (a first look): smaller grid, fewer frames");
  study->add_option("--state-file", s->state_file, "where the study keeps its queue group (for --resume)");
  study->add_flag("--resume", s->resume, "carry on a study whose queue items are already in the daemon (after a restart)");
  study->callback([&global, s] {
    std::vector<std::string> args{s->study};
    if (!s->output.empty()) args.insert(args.end(), {"-o", s->output});
    for (const auto& o : s->overrides) args.insert(args.end(), {"--set", o});
    if (!s->state_file.empty()) args.insert(args.end(), {"--state-file", s->state_file});
    if (s->dry_run) args.push_back("--dry-run");
    if (s->small) args.push_back("--small");
    if (s->resume) args.push_back("--resume");
    if (global.json) args.push_back("--json");
    // 0 done, 2 usage, 3 the daemon, 4 a campaign of the study failed (named).
    exec_module(global, "colorlab.study", args);
  });
}

}  // namespace colorlab::cli
