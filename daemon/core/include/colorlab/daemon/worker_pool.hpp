#pragma once
// colorlabd's worker pool: the heavy computations a campaign or a request asks for (fits, analyses,
// dry runs' analyses) run here, on a few threads of their own, so that the io thread — where every
// `main` route, the operator's answers, campaign starts and systemd's watchdog ping are served —
// never waits behind them (issue 27). A job's result is handed back on the io thread.
//
// Threads and locks: `threads` worker threads, started by the constructor and joined by shutdown()
// (or the destructor). One mutex guards the queue and the counters; a job runs without it. A job
// must own (copy) everything it reads: it runs while the io thread goes on changing live state.
//
// The queue is bounded: a job submitted while `queue_limit` jobs already wait is refused with
// WorkerPoolFull (503 with Retry-After on the API), rather than piling up work nobody waits for.
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/async_result.hpp>
#include <boost/asio/awaitable.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/use_awaitable.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/core/error.hpp"

namespace colorlab::daemon {

struct WorkerPoolOptions {
  std::size_t threads = 1;      // 2 cores on a lab PC: one fit at a time leaves a core to the rest
  std::size_t queue_limit = 8;  // jobs waiting beyond the running ones
  // A test hook (COLORLAB_TEST_WORKER_LATCH): before each job, the worker creates `<latch>.held`
  // and waits until `<latch>.release` exists, so a test can hold a job and see what still answers.
  std::filesystem::path latch;
  // Nice steps the workers run below their creator ([priority] heavy_work_nice, thread_priority.hpp):
  // the io thread and the HTTP pool then preempt a fit. 0 for the step committer, which a step waits on.
  int nice = 0;
  std::string name = "workers";  // the threads' name (top -H, /proc/PID/task/TID/comm); 15 characters at most
};

// The queue is full: the caller should try again shortly (retry_after_s).
class WorkerPoolFull : public Error {
 public:
  explicit WorkerPoolFull(const std::string& what, std::size_t limit);
  int retry_after_s() const { return 2; }
};

// Campaigns' analyses are always taken: each execution waits for its own, so they are bounded by the
// executions running, and refusing one would fail a night's run for a busy moment. Requests' jobs
// (a dry run asked over the API) are bounded by the queue.
enum class Admission {
  bounded,
  always
};

class WorkerPool {
 public:
  // Results are handed back on `results` (the io thread's executor).
  WorkerPool(boost::asio::any_io_executor results, WorkerPoolOptions options);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  // Runs `job` on a worker; `done` is posted to the results executor with its result or the
  // exception it threw (an exception that is not colorlab::Error arrives as Error{internal}).
  // Throws WorkerPoolFull when the queue is full (bounded admission), Error{aborted} after shutdown().
  void submit(std::string what, std::function<nlohmann::json()> job,
              std::function<void(std::exception_ptr, nlohmann::json)> done, Admission admission = Admission::bounded);

  // The same as a coroutine on the io thread: suspends until the job's result is back, and throws
  // what the job threw (or the refusal).
  boost::asio::awaitable<nlohmann::json> run(std::string what, std::function<nlohmann::json()> job,
                                             Admission admission = Admission::bounded);

  // Reserves a place in the bounded queue for a request's work made of several jobs (a dry run, whose
  // analyses are then submitted with Admission::always); the place is given back when the returned
  // handle is dropped. Throws WorkerPoolFull when the queue (with places reserved) is full.
  std::shared_ptr<void> admit(const std::string& what);

  // Stops taking jobs; jobs still queued end with Error{aborted}; running ones finish; joins.
  void shutdown();

  std::size_t queued() const;
  std::size_t running() const;

 private:
  struct Job {
    std::string what;
    std::function<nlohmann::json()> work;
    std::function<void(std::exception_ptr, nlohmann::json)> done;
  };
  void work();
  void hold_at_latch() const;

  boost::asio::any_io_executor results_;
  WorkerPoolOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<Job> queue_;
  std::size_t running_ = 0;
  // Places admit() holds; shared, so that a handle dropped after the pool (a coroutine frame destroyed
  // with the io_context) touches nothing freed.
  std::shared_ptr<std::atomic<std::size_t>> reserved_ = std::make_shared<std::atomic<std::size_t>>(0);
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

// The pool's options from the environment's test hook (COLORLAB_TEST_WORKER_LATCH) over `base`.
WorkerPoolOptions with_test_hooks(WorkerPoolOptions base);

}  // namespace colorlab::daemon
