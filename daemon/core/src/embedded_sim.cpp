#include "colorlab/daemon/embedded_sim.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

#include "colorlab/core/error.hpp"
#include "colorlab/core/log.hpp"

namespace colorlab::daemon {

std::filesystem::path default_sim_binary() {
  if (const char* env = std::getenv("COLORLAB_SIM"); env && *env) return env;
  std::error_code ec;
  auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return "colorlab-sim";
  // The build tree puts both in bin/; an installed colorlabd is in <prefix>/sbin beside <prefix>/bin/colorlab-sim.
  auto sibling = self.parent_path() / "colorlab-sim";
  auto in_bin = self.parent_path().parent_path() / "bin" / "colorlab-sim";
  if (!std::filesystem::exists(sibling, ec) && std::filesystem::exists(in_bin, ec)) return in_bin;
  return sibling;
}

EmbeddedSim::EmbeddedSim(const std::filesystem::path& sim_binary, const SimulatorConfig& config,
                         const std::filesystem::path& scratch_dir, std::chrono::milliseconds startup_timeout) {
  std::vector<std::string> args{sim_binary.string()};
  if (!scratch_dir.empty()) {
    std::error_code ec;
    args.push_back("--scratch-dir");
    args.push_back(std::filesystem::absolute(scratch_dir, ec).string());
  }
  if (config.config) {
    args.push_back("--config");
    args.push_back(config.config->string());
  }
  if (config.time_scale) {
    args.push_back("--time-scale");
    args.push_back(std::to_string(*config.time_scale));
  }
  if (config.seed) {
    args.push_back("--seed");
    args.push_back(std::to_string(*config.seed));
  }

  // Built before fork: the child of a threaded process may call only async-signal-safe functions until exec, and
  // allocating could deadlock on a malloc lock another thread held at the fork.
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string exec_failed = "colorlabd: cannot run " + args.front() + "\n";

  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw Error(ErrorClass::io_error, std::string("pipe: ") + std::strerror(errno));
  pid_t parent = ::getpid();
  pid_ = ::fork();
  if (pid_ < 0) throw Error(ErrorClass::io_error, std::string("fork: ") + std::strerror(errno));
  if (pid_ == 0) {
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != parent) _exit(1);
    // Below the daemon (docs/configuration.md, "CPU priority"): before exec, so all its threads inherit it.
    if (config.nice > 0) {
      errno = 0;
      const int now = ::getpriority(PRIO_PROCESS, 0);
      if (errno == 0) ::setpriority(PRIO_PROCESS, 0, now + config.nice > 19 ? 19 : now + config.nice);
    }
    ::dup2(fds[1], STDOUT_FILENO);
    ::execv(argv[0], argv.data());
    [[maybe_unused]] const auto written = ::write(STDERR_FILENO, exec_failed.data(), exec_failed.size());
    _exit(127);
  }
  ::close(fds[1]);
  stdout_fd_ = fds[0];

  std::string line;
  auto deadline = std::chrono::steady_clock::now() + startup_timeout;
  while (line.find('\n') == std::string::npos) {
    auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) break;
    pollfd p{stdout_fd_, POLLIN, 0};
    int rc = ::poll(&p, 1, static_cast<int>(left.count()));
    if (rc <= 0) continue;
    char buf[4096];
    ssize_t n = ::read(stdout_fd_, buf, sizeof buf);
    if (n <= 0) break;
    line.append(buf, static_cast<std::size_t>(n));
  }
  auto nl = line.find('\n');
  if (nl == std::string::npos) {
    this->~EmbeddedSim();
    throw Error(ErrorClass::no_comms, "the simulated lab (" + sim_binary.string() + ") did not announce itself",
                "run it by hand to see why: " + sim_binary.string());
  }
  announcement_ = nlohmann::json::parse(line.substr(0, nl), nullptr, false);
  if (announcement_.is_discarded() || !announcement_.contains("instruments")) {
    this->~EmbeddedSim();
    throw Error(ErrorClass::protocol_error, "the simulated lab's announcement is not the expected JSON: " + line);
  }
  log::info("colorlabd", "simulated lab running (pid " + std::to_string(pid_) + ")");
}

EmbeddedSim::~EmbeddedSim() {
  if (pid_ > 0) {
    ::kill(pid_, SIGTERM);
    int status = 0;
    // Give it a moment to close its ptys; then make sure.
    for (int i = 0; i < 50 && ::waitpid(pid_, &status, WNOHANG) == 0; ++i) ::usleep(20000);
    if (::waitpid(pid_, &status, WNOHANG) == 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, &status, 0);
    }
    pid_ = -1;
  }
  if (stdout_fd_ >= 0) {
    ::close(stdout_fd_);
    stdout_fd_ = -1;
  }
}

std::vector<drivers::InstrumentConfig> EmbeddedSim::instruments() const {
  std::vector<drivers::InstrumentConfig> out;
  for (const auto& i : announcement_["instruments"]) {
    drivers::InstrumentConfig c;
    c.id = i.value("id", std::string());
    c.kind = i.value("kind", std::string());
    // Cameras are reached by network address rather than a device path.
    c.port = i.value("port", i.value("address", std::string()));
    c.simulated = true;
    if (i.contains("driver_options")) c.options = i["driver_options"];
    if (!c.port.empty()) out.push_back(std::move(c));
  }
  return out;
}

std::vector<campaigns::AbsentInstrument> EmbeddedSim::absent_instruments() const {
  std::vector<campaigns::AbsentInstrument> out;
  for (const auto& i : announcement_.value("absent", nlohmann::json::array())) {
    out.push_back({i.value("id", std::string()), i.value("kind", std::string()),
                   i.value("port", i.value("address", std::string())), true,
                   "the simulated lab could not start it: " + i.value("reason", std::string("no reason given"))});
  }
  return out;
}

}  // namespace colorlab::daemon
