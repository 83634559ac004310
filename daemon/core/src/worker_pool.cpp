#include "colorlab/daemon/worker_pool.hpp"

#include <chrono>
#include <cstdlib>
#include <fstream>

#include <pthread.h>

#include "colorlab/core/log.hpp"
#include "colorlab/core/thread_priority.hpp"

namespace colorlab::daemon {

namespace asio = boost::asio;
using nlohmann::json;

WorkerPoolFull::WorkerPoolFull(const std::string& what, std::size_t limit)
    : Error(ErrorClass::io_error,  // 503: the daemon is fine, only busy for now
            "colorlabd is busy: " + std::to_string(limit) + " computations already wait for its worker pool, so " +
                what + " was not started",
            "try again in a few seconds") {}

WorkerPool::WorkerPool(asio::any_io_executor results, WorkerPoolOptions options)
    : results_(std::move(results)), options_(std::move(options)) {
  if (options_.threads == 0) options_.threads = 1;
  threads_.reserve(options_.threads);
  for (std::size_t i = 0; i < options_.threads; ++i) threads_.emplace_back([this] { work(); });
}

WorkerPool::~WorkerPool() { shutdown(); }

void WorkerPool::submit(std::string what, std::function<json()> job, std::function<void(std::exception_ptr, json)> done,
                        Admission admission) {
  {
    std::lock_guard lock(mutex_);
    if (stopping_) throw Error(ErrorClass::aborted, "colorlabd is shutting down: " + what + " was not started");
    if (admission == Admission::bounded && queue_.size() + reserved_->load() >= options_.queue_limit) throw WorkerPoolFull(what, options_.queue_limit);
    queue_.push_back(Job{std::move(what), std::move(job), std::move(done)});
  }
  wake_.notify_one();
}

namespace {

// Named, and handed to async_initiate outside any co_await: GCC 12 destroys some temporaries of a
// co_await expression twice.
struct RunInitiation {
  WorkerPool* pool;
  asio::any_io_executor results;
  std::string what;
  std::function<json()> job;
  Admission admission;

  template <class Handler>
  void operator()(Handler handler) {
    // The awaitable's handler is move-only; the pool's callbacks are std::function.
    auto shared = std::make_shared<Handler>(std::move(handler));
    try {
      pool->submit(
          std::move(what), std::move(job), [shared](std::exception_ptr e, json j) { (*shared)(e, std::move(j)); },
          admission);
    } catch (...) {
      // A refusal arrives like a job's error, and never inside the initiation.
      asio::post(results, [shared, e = std::current_exception()] { (*shared)(e, json()); });
    }
  }
};

}  // namespace

asio::awaitable<json> WorkerPool::run(std::string what, std::function<json()> job, Admission admission) {
  return asio::async_initiate<const asio::use_awaitable_t<>&, void(std::exception_ptr, json)>(
      RunInitiation{this, results_, std::move(what), std::move(job), admission}, asio::use_awaitable);
}

std::shared_ptr<void> WorkerPool::admit(const std::string& what) {
  {
    std::lock_guard lock(mutex_);
    if (stopping_) throw Error(ErrorClass::aborted, "colorlabd is shutting down: " + what + " was not started");
    if (queue_.size() + reserved_->load() >= options_.queue_limit) throw WorkerPoolFull(what, options_.queue_limit);
    ++*reserved_;
  }
  return std::shared_ptr<void>(nullptr, [reserved = reserved_](void*) { --*reserved; });
}

void WorkerPool::shutdown() {
  std::deque<Job> cancelled;
  {
    std::lock_guard lock(mutex_);
    if (stopping_ && threads_.empty()) return;
    stopping_ = true;
    cancelled.swap(queue_);
  }
  wake_.notify_all();
  for (auto& job : cancelled) {
    auto e = std::make_exception_ptr(
        Error(ErrorClass::aborted, "colorlabd stopped before " + job.what + " ran", "start it again after the restart"));
    asio::post(results_, [done = std::move(job.done), e] { done(e, json()); });
  }
  for (auto& t : threads_) {
    if (t.joinable()) t.join();
  }
  threads_.clear();
}

std::size_t WorkerPool::queued() const {
  std::lock_guard lock(mutex_);
  return queue_.size();
}

std::size_t WorkerPool::running() const {
  std::lock_guard lock(mutex_);
  return running_;
}

void WorkerPool::hold_at_latch() const {
  if (options_.latch.empty()) return;
  auto held = options_.latch;
  held += ".held";
  auto release = options_.latch;
  release += ".release";
  { std::ofstream(held) << "held\n"; }
  // Polled, not timed: the test decides when the job may go on; shutdown lets it go too.
  while (!std::filesystem::exists(release)) {
    {
      std::lock_guard lock(mutex_);
      if (stopping_) return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

void WorkerPool::work() {
  pthread_setname_np(pthread_self(), options_.name.substr(0, 15).c_str());
  core::lower_this_thread(options_.nice, "a worker-pool thread (" + options_.name + ")");
  for (;;) {
    Job job;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping, nothing left
      job = std::move(queue_.front());
      queue_.pop_front();
      ++running_;
    }
    hold_at_latch();
    std::exception_ptr error;
    json result;
    try {
      result = job.work();
    } catch (const Error&) {
      error = std::current_exception();
    } catch (const std::exception& e) {
      error = std::make_exception_ptr(Error(ErrorClass::internal, job.what + " failed: " + e.what()));
    } catch (...) {
      error = std::make_exception_ptr(Error(ErrorClass::internal, job.what + " failed with an unknown exception"));
    }
    {
      std::lock_guard lock(mutex_);
      --running_;
    }
    asio::post(results_, [done = std::move(job.done), error, result = std::move(result)]() mutable {
      done(error, std::move(result));
    });
  }
}

WorkerPoolOptions with_test_hooks(WorkerPoolOptions base) {
  if (const char* latch = std::getenv("COLORLAB_TEST_WORKER_LATCH"); latch && *latch) {
    base.latch = latch;
    log::warning("workers", std::string("test hook: every job waits for ") + latch + ".release");
  }
  return base;
}

}  // namespace colorlab::daemon
