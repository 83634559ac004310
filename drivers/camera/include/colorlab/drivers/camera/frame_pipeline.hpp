#pragma once
// Two-stage pipeline: the caller's thread produces items (captures frames) while a consumer
// thread owned by the pipeline processes the previous ones (decodes and accumulates). A bounded
// queue between them caps memory at `depth` frames, so a series takes max(capture, decode) per
// frame instead of their sum.
//
// Failure rules, which make a partial series visible as partial:
//  * the producer throws -> no more items are produced; items already queued are still consumed;
//  * the consumer throws -> the producer stops before its next item; queued items are dropped.
// Either way the first exception is returned and `consumed` counts what was really delivered.
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

#include "colorlab/core/thread_priority.hpp"

namespace colorlab::drivers::camera {

struct PipelineRun {
  std::size_t requested = 0;
  std::size_t produced = 0;
  std::size_t consumed = 0;
  std::exception_ptr error;  // first failure, from either stage
  bool error_in_consumer = false;
  std::chrono::nanoseconds produce_time{0};  // summed time inside produce()
  std::chrono::nanoseconds consume_time{0};  // summed time inside consume()
  std::chrono::nanoseconds wall_time{0};
  bool complete() const { return !error && consumed == requested; }
};

template <class Item>
class FramePipeline {
 public:
  using Produce = std::function<Item(std::size_t index)>;
  using Consume = std::function<void(Item&&, std::size_t index)>;

  explicit FramePipeline(std::size_t depth = 2) : depth_(depth == 0 ? 1 : depth) {
    consumer_ = std::thread([this] {
      // Decoding full-size RAW frames is heavy: below the daemon's answering threads (issue 27).
      core::become_heavy_thread("decode");
      consumer_loop();
    });
  }
  ~FramePipeline() {
    {
      std::lock_guard lock(mutex_);
      shutdown_ = true;
    }
    changed_.notify_all();
    consumer_.join();
  }
  FramePipeline(const FramePipeline&) = delete;
  FramePipeline& operator=(const FramePipeline&) = delete;

  // Runs one series; blocks the calling thread until every produced item is consumed.
  // Not re-entrant: one series at a time per pipeline.
  PipelineRun run(std::size_t n, const Produce& produce, const Consume& consume) {
    using clock = std::chrono::steady_clock;
    const auto start = clock::now();
    {
      std::lock_guard lock(mutex_);
      run_ = PipelineRun{};
      run_.requested = n;
      consume_ = &consume;
      queue_.clear();
      producer_done_ = false;
      consumer_failed_ = false;
      active_ = true;
    }
    changed_.notify_all();

    for (std::size_t i = 0; i < n; ++i) {
      {
        std::unique_lock lock(mutex_);
        changed_.wait(lock, [&] { return queue_.size() < depth_ || consumer_failed_; });
        if (consumer_failed_) break;
      }
      const auto t0 = clock::now();
      std::optional<Item> item;
      try {
        item.emplace(produce(i));
      } catch (...) {
        std::lock_guard lock(mutex_);
        run_.produce_time += clock::now() - t0;
        if (!run_.error) run_.error = std::current_exception();
        break;
      }
      std::lock_guard lock(mutex_);
      run_.produce_time += clock::now() - t0;
      ++run_.produced;
      queue_.emplace_back(std::move(*item), i);
      changed_.notify_all();
    }

    std::unique_lock lock(mutex_);
    producer_done_ = true;
    changed_.notify_all();
    changed_.wait(lock, [&] { return !active_; });
    run_.wall_time = clock::now() - start;
    consume_ = nullptr;
    return run_;
  }

 private:
  void consumer_loop() {
    using clock = std::chrono::steady_clock;
    std::unique_lock lock(mutex_);
    for (;;) {
      changed_.wait(lock, [&] { return shutdown_ || (active_ && (!queue_.empty() || producer_done_)); });
      if (shutdown_) return;
      if (queue_.empty()) {  // producer finished and everything is consumed
        active_ = false;
        changed_.notify_all();
        continue;
      }
      auto [item, index] = std::move(queue_.front());
      queue_.pop_front();
      changed_.notify_all();
      if (consumer_failed_) continue;  // drain without delivering after a consumer failure
      const Consume* consume = consume_;
      lock.unlock();
      const auto t0 = clock::now();
      std::exception_ptr failure;
      try {
        (*consume)(std::move(item), index);
      } catch (...) {
        failure = std::current_exception();
      }
      const auto spent = clock::now() - t0;
      lock.lock();
      run_.consume_time += spent;
      if (failure) {
        consumer_failed_ = true;
        if (!run_.error) {
          run_.error = failure;
          run_.error_in_consumer = true;
        }
      } else {
        ++run_.consumed;
      }
      changed_.notify_all();
    }
  }

  const std::size_t depth_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::pair<Item, std::size_t>> queue_;
  const Consume* consume_ = nullptr;
  PipelineRun run_;
  bool active_ = false;
  bool producer_done_ = false;
  bool consumer_failed_ = false;
  bool shutdown_ = false;
  std::thread consumer_;
};

}  // namespace colorlab::drivers::camera
