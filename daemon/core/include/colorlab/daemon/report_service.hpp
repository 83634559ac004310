#pragma once
// A finished run's report (the dissertation's tables and figures as one HTML file), made by the Python
// client's report package in a child process and kept under <state>/reports, so the API and the web
// console can serve it: GET /v1/runs/{id}/report (api.cpp). A study's report covers the runs of a queued
// sequence's group in one file: GET /v1/queue/groups/{id}/report (queue_api.cpp).
#include <chrono>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <sys/types.h>

namespace colorlab::daemon {

class ReportService {
 public:
  struct Options {
    std::filesystem::path directory;    // <state>/reports
    std::filesystem::path unix_socket;  // the daemon's own socket: the child reads the run through the API
    std::string python = "/usr/bin/python3";
    std::string version;  // part of the file name: a new colorlabd makes its reports anew
    std::chrono::seconds timeout{600};
    std::chrono::seconds retry_after_failure{60};
    // Nice steps the report thread runs below the daemon, and so the Python client it spawns, which
    // inherits them ([priority] heavy_work_nice; core/thread_priority.hpp).
    int nice = 0;
  };
  struct State {
    enum class Kind {
      ready,
      generating,
      failed
    } kind = Kind::generating;
    std::filesystem::path file;  // ready: the HTML
    std::string error;           // failed: why, with the end of the child's output
  };

  explicit ReportService(Options options);
  ~ReportService();  // stops a child still running and joins the worker
  ReportService(const ReportService&) = delete;
  ReportService& operator=(const ReportService&) = delete;

  // For a finished run: its report when made; else starts making it (one at a time, in request order)
  // and says so. A failure is reported for retry_after_failure, then the next request tries again.
  State request(const std::string& run_id);
  // The same for one report of several runs, kept under `key` (a name of its own, not a run id).
  State request(const std::string& key, const std::vector<std::string>& run_ids);

 private:
  struct Failure {
    std::string error;
    std::chrono::steady_clock::time_point at;
  };
  std::filesystem::path file_for(const std::string& key) const;
  void work();
  std::string make(const std::string& key, const std::vector<std::string>& run_ids);  // empty, else the reason

  Options options_;
  std::mutex mutex_;
  std::condition_variable wake_;
  struct Job {
    std::string key;
    std::vector<std::string> run_ids;
  };
  std::deque<Job> queue_;
  std::map<std::string, Failure> failures_;
  std::string current_;
  pid_t child_ = -1;
  bool stopping_ = false;
  std::thread worker_;
};

}  // namespace colorlab::daemon
