#include "report_command.hpp"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>

#include "colorlab/core/data_paths.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::cli {

namespace fs = std::filesystem;

namespace {

struct ReportOptions {
  std::vector<std::string> runs;
  std::string output;
};

// Replaces this process with the report module, so its output, progress and exit code (0 written,
// 2 usage, 3 run or daemon not found) are the command's own.
[[noreturn]] void exec_report(const GlobalOptions& g, const ReportOptions& o) {
  const char* python = std::getenv("COLORLAB_PYTHON");
  const std::string interpreter = python && *python ? python : "/usr/bin/python3";
  std::vector<std::string> args{interpreter, "-m", "colorlab.report"};
  args.insert(args.end(), o.runs.begin(), o.runs.end());
  if (!o.output.empty()) args.insert(args.end(), {"-o", o.output});
  if (!g.socket.empty()) {
    args.insert(args.end(), {"--socket", g.socket});
  } else {
    args.insert(args.end(), {"--url", g.url});
  }
  // The key goes by environment, not argv, where any user's `ps` would see it.
  if (!g.key.empty()) ::setenv("COLORLAB_API_KEY", g.key.c_str(), 1);
  if (!g.cacert.empty()) ::setenv("REQUESTS_CA_BUNDLE", g.cacert.c_str(), 1);
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
              "reports need Python 3 with matplotlib, numpy, pandas and requests: scripts/setup.sh installs them");
}

}  // namespace

void add_report_command(CLI::App& app, GlobalOptions& global) {
  auto o = std::make_shared<ReportOptions>();
  auto* cmd = app.add_subcommand(
      "report",
      "Write the dissertation's tables and figures for stored runs (frame-average, cabinet-grid, chart-read, "
      "characterize-camera, luminance-spot) as one self-contained HTML file, each beside the published numbers; "
      "prints its path");
  cmd->add_option("runs", o->runs, "run ids (colorlab runs lists them)")->required();
  cmd->add_option("-o,--output", o->output, "HTML file to write (default: ./report-<first run>.html)");
  cmd->callback([&global, o] {
    for (const auto& run : o->runs) {
      if (run.empty() || run.find_first_not_of("0123456789abcdefABCDEF-") != std::string::npos)
        throw Error(ErrorClass::bad_parameter, "'" + run + "' is not a run id", "colorlab runs lists them");
    }
    exec_report(global, *o);
  });
}

}  // namespace colorlab::cli
