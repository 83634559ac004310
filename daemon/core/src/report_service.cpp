#include "colorlab/daemon/report_service.hpp"

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

#include <fcntl.h>
#include <pthread.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include "colorlab/core/data_paths.hpp"
#include "colorlab/core/log.hpp"
#include "colorlab/core/thread_priority.hpp"

extern char** environ;

namespace colorlab::daemon {

namespace fs = std::filesystem;

ReportService::ReportService(Options options) : options_(std::move(options)) {
  std::error_code ec;
  fs::create_directories(options_.directory, ec);
  worker_ = std::thread([this] { work(); });
}

ReportService::~ReportService() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    if (child_ > 0) ::kill(child_, SIGTERM);
  }
  wake_.notify_all();
  if (worker_.joinable()) worker_.join();
}

fs::path ReportService::file_for(const std::string& key) const {
  return options_.directory / (key + "-" + options_.version + ".html");
}

ReportService::State ReportService::request(const std::string& run_id) { return request(run_id, {run_id}); }

ReportService::State ReportService::request(const std::string& key, const std::vector<std::string>& run_ids) {
  State s;
  std::error_code ec;
  const auto file = file_for(key);
  std::lock_guard lock(mutex_);
  if (fs::is_regular_file(file, ec)) {
    s.kind = State::Kind::ready;
    s.file = file;
    return s;
  }
  if (auto f = failures_.find(key); f != failures_.end()) {
    if (std::chrono::steady_clock::now() - f->second.at < options_.retry_after_failure) {
      s.kind = State::Kind::failed;
      s.error = f->second.error;
      return s;
    }
    failures_.erase(f);
  }
  if (current_ != key && std::none_of(queue_.begin(), queue_.end(), [&](const Job& j) { return j.key == key; })) {
    queue_.push_back(Job{key, run_ids});
    wake_.notify_one();
  }
  s.kind = State::Kind::generating;
  return s;
}

void ReportService::work() {
  pthread_setname_np(pthread_self(), "reports");
  core::lower_this_thread(options_.nice, "the report thread");
  std::unique_lock lock(mutex_);
  while (true) {
    wake_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
    if (stopping_) return;
    const Job job = queue_.front();
    queue_.pop_front();
    current_ = job.key;
    lock.unlock();
    const std::string error = make(job.key, job.run_ids);
    lock.lock();
    if (!error.empty() && !stopping_) {
      log::warning("reports", "report " + job.key + " failed: " + error);
      failures_[job.key] = Failure{error, std::chrono::steady_clock::now()};
    }
    current_.clear();
  }
}

namespace {

std::string tail_of(const fs::path& file, std::size_t bytes) {
  std::ifstream in(file, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), {});
  if (text.size() > bytes) text = "…" + text.substr(text.size() - bytes);
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  return text;
}

}  // namespace

std::string ReportService::make(const std::string& key, const std::vector<std::string>& run_ids) {
  const auto file = file_for(key);
  const auto log_file = options_.directory / (key + ".log");
  std::vector<std::string> args{options_.python, "-m", "colorlab.report"};
  args.insert(args.end(), run_ids.begin(), run_ids.end());
  for (const char* a : {"-o", file.c_str(), "--socket", options_.unix_socket.c_str()}) args.emplace_back(a);
  // The child's environment: the daemon's, plus where the package is, a matplotlib cache it may write
  // (a service's HOME may not be writable), and no key (the Unix socket may read everything).
  std::vector<std::string> env;
  for (char** e = environ; e && *e; ++e) {
    std::string_view v(*e);
    if (v.rfind("PYTHONPATH=", 0) == 0 || v.rfind("MPLCONFIGDIR=", 0) == 0 || v.rfind("COLORLAB_API_KEY=", 0) == 0 ||
        v.rfind("COLORLAB_URL=", 0) == 0 || v.rfind("COLORLAB_SOCKET=", 0) == 0)
      continue;
    env.emplace_back(v);
  }
  if (auto dir = paths::python_client_dir(); !dir.empty()) env.push_back("PYTHONPATH=" + dir.string());
  env.push_back("MPLCONFIGDIR=" + (options_.directory / ".matplotlib").string());
  env.push_back("MPLBACKEND=Agg");

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, log_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0640);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  // None of the daemon's sockets, database or listening ports stay open in the child.
  posix_spawn_file_actions_addclosefrom_np(&actions, 3);
  std::vector<char*> argv, envp;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  for (auto& e : env) envp.push_back(e.data());
  envp.push_back(nullptr);
  pid_t pid = -1;
  const int spawned = ::posix_spawn(&pid, options_.python.c_str(), &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) return "cannot run " + options_.python + ": " + std::strerror(spawned);
  {
    std::lock_guard lock(mutex_);
    child_ = pid;
    if (stopping_) ::kill(pid, SIGTERM);
  }
  const auto deadline = std::chrono::steady_clock::now() + options_.timeout;
  int status = 0;
  bool timed_out = false;
  while (true) {
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    if (r < 0 && errno != EINTR) break;
    if (!timed_out && std::chrono::steady_clock::now() > deadline) {
      timed_out = true;
      ::kill(pid, SIGKILL);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  {
    std::lock_guard lock(mutex_);
    child_ = -1;
  }
  std::error_code ec;
  if (timed_out) return "the report took longer than " + std::to_string(options_.timeout.count()) + " s and was stopped";
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0 && fs::is_regular_file(file, ec)) return {};
  std::string why = WIFEXITED(status) ? "the report module exited " + std::to_string(WEXITSTATUS(status))
                                      : "the report module was killed by signal " + std::to_string(WTERMSIG(status));
  if (WIFEXITED(status) && WEXITSTATUS(status) == 1) why += " (is python3-matplotlib installed? scripts/setup.sh installs it)";
  return why + ": " + tail_of(log_file, 1500);
}

}  // namespace colorlab::daemon
