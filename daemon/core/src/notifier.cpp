#include "colorlab/daemon/notifier.hpp"

#include <curl/curl.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>

#include "colorlab/core/ids.hpp"
#include "colorlab/core/log.hpp"

extern char** environ;

namespace colorlab::daemon {

using nlohmann::json;

namespace {

std::string hostname() {
  char name[256] = {};
  if (::gethostname(name, sizeof name - 1) != 0) return "";
  return name;
}

// scheme://host[:port] only: a webhook's path or query often holds its secret, and logs are read widely.
std::string url_origin(const std::string& url) {
  auto scheme = url.find("://");
  if (scheme == std::string::npos) return "(webhook)";
  auto end = url.find_first_of("/?#", scheme + 3);
  std::string origin = url.substr(0, end);
  if (auto at = origin.rfind('@'); at != std::string::npos) origin = origin.substr(0, scheme + 3) + origin.substr(at + 1);
  return origin;
}

}  // namespace

Notifier::Notifier(NotifyConfig config) : config_(std::move(config)), host_(hostname()) {
  // Once, before the worker exists: curl_global_init is not thread-safe.
  if (!config_.webhook.empty()) curl_global_init(CURL_GLOBAL_DEFAULT);
  worker_ = std::thread([this] { work(); });
}

Notifier::~Notifier() {
  std::size_t dropped = 0;
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    dropped = queue_.size();
    queue_.clear();
  }
  wake_.notify_all();
  if (worker_.joinable()) worker_.join();
  if (dropped > 0) log::warning("notify", std::to_string(dropped) + " notification(s) not delivered: colorlabd is stopping");
  if (!config_.webhook.empty()) curl_global_cleanup();
}

void Notifier::notify(const std::string& event, const json& details) {
  if (!config_.enabled()) return;
  if (std::find(config_.events.begin(), config_.events.end(), event) == config_.events.end()) return;
  json document{{"event", event}, {"time", now_iso8601()}, {"host", host_}};
  if (details.is_object()) document.update(details);
  {
    std::lock_guard lock(mutex_);
    if (stopping_) return;
    if (queue_.size() >= kMaxQueued) {
      log::warning("notify", "dropped a '" + event + "' notification: " + std::to_string(kMaxQueued) +
                                 " are still waiting (is the command or webhook hanging?)");
      return;
    }
    queue_.push_back(std::move(document));
  }
  wake_.notify_one();
}

void Notifier::work() {
  for (;;) {
    json document;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (stopping_) return;
      document = std::move(queue_.front());
      queue_.pop_front();
    }
    deliver(document);
  }
}

void Notifier::deliver(const json& document) {
  const std::string body = document.dump();
  const std::string event = document.value("event", std::string());
  if (!config_.command.empty()) run_command(body, event);
  if (!config_.webhook.empty()) post_webhook(body);
}

// The document on the command's stdin from a sealed in-memory file: no pipe that a command which
// never reads could fill, and no SIGPIPE for the daemon when it exits early.
void Notifier::run_command(const std::string& body, const std::string& event) {
  const std::string& program = config_.command.front();
  int input = ::memfd_create("colorlab-notification", MFD_CLOEXEC);
  if (input < 0) {
    log::warning("notify", "cannot run " + program + ": memfd_create: " + std::strerror(errno));
    return;
  }
  std::size_t written = 0;
  while (written < body.size()) {
    ssize_t n = ::write(input, body.data() + written, body.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    written += static_cast<std::size_t>(n);
  }
  ::lseek(input, 0, SEEK_SET);

  std::vector<std::string> env_strings;
  for (char** e = environ; e && *e; ++e) {
    if (std::strncmp(*e, "COLORLAB_EVENT=", 15) != 0) env_strings.emplace_back(*e);
  }
  env_strings.push_back("COLORLAB_EVENT=" + event);
  std::vector<char*> envp;
  for (auto& e : env_strings) envp.push_back(e.data());
  envp.push_back(nullptr);
  std::vector<std::string> args = config_.command;
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, input, 0);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  // The daemon's sockets, database and instrument ports are none of the command's business.
  posix_spawn_file_actions_addclosefrom_np(&actions, 3);
  pid_t pid = -1;
  const int spawned = ::posix_spawnp(&pid, program.c_str(), &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  ::close(input);
  if (spawned != 0) {
    log::warning("notify", "cannot run " + program + ": " + std::strerror(spawned));
    return;
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(config_.timeout_s);
  int status = 0;
  for (;;) {
    pid_t done = ::waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) {
      log::warning("notify", program + ": waitpid: " + std::strerror(errno));
      return;
    }
    if (std::chrono::steady_clock::now() >= deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      log::warning("notify", program + " took longer than " + std::to_string(config_.timeout_s) + " s and was killed");
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) != 0) {
    log::warning("notify", program + " exited with status " + std::to_string(WEXITSTATUS(status)));
  } else if (WIFSIGNALED(status)) {
    log::warning("notify", program + " was killed by signal " + std::to_string(WTERMSIG(status)));
  }
}

void Notifier::post_webhook(const std::string& body) {
  const std::string where = url_origin(config_.webhook);
  CURL* curl = curl_easy_init();
  if (!curl) {
    log::warning("notify", "cannot POST to " + where + ": curl_easy_init failed");
    return;
  }
  char error[CURL_ERROR_SIZE] = {};
  curl_slist* headers = curl_slist_append(nullptr, "Content-Type: application/json");
  const long timeout_ms = static_cast<long>(config_.timeout_s * 1000);
  curl_easy_setopt(curl, CURLOPT_URL, config_.webhook.c_str());
  curl_easy_setopt(curl, CURLOPT_PROTOCOLS_STR, "http,https");
  curl_easy_setopt(curl, CURLOPT_POST, 1L);
  curl_easy_setopt(curl, CURLOPT_POSTFIELDS, body.c_str());
  curl_easy_setopt(curl, CURLOPT_POSTFIELDSIZE, static_cast<long>(body.size()));
  curl_easy_setopt(curl, CURLOPT_HTTPHEADER, headers);
  curl_easy_setopt(curl, CURLOPT_USERAGENT, "colorlabd");
  curl_easy_setopt(curl, CURLOPT_TIMEOUT_MS, timeout_ms);
  curl_easy_setopt(curl, CURLOPT_CONNECTTIMEOUT_MS, timeout_ms);
  // A worker thread of a multi-threaded daemon: no SIGALRM for name resolution.
  curl_easy_setopt(curl, CURLOPT_NOSIGNAL, 1L);
  curl_easy_setopt(curl, CURLOPT_ERRORBUFFER, error);
  // The answer's body is not ours to print (it may echo the request); discard it.
  curl_easy_setopt(
      curl, CURLOPT_WRITEFUNCTION, +[](char*, size_t size, size_t n, void*) -> size_t { return size * n; });
  const CURLcode rc = curl_easy_perform(curl);
  long status = 0;
  curl_easy_getinfo(curl, CURLINFO_RESPONSE_CODE, &status);
  curl_slist_free_all(headers);
  curl_easy_cleanup(curl);
  if (rc != CURLE_OK) {
    log::warning("notify", "POST to " + where + " failed: " + (error[0] ? std::string(error) : curl_easy_strerror(rc)));
  } else if (status < 200 || status >= 300) {
    log::warning("notify", "POST to " + where + " answered HTTP " + std::to_string(status));
  }
}

}  // namespace colorlab::daemon
