#include "ship_read_ahead.hpp"

#include <chrono>

namespace colorlab::fleet {

namespace {
double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}
}  // namespace

ReadAhead::ReadAhead(const std::filesystem::path& database, std::string bench_id, std::vector<EndedRun> runs,
                     std::int64_t position, std::int64_t max_measurements)
    : reader_(database),
      bench_id_(std::move(bench_id)),
      runs_(std::move(runs)),
      position_(position),
      max_measurements_(max_measurements),
      thread_([this] { work(); }) {}

ReadAhead::~ReadAhead() {
  {
    std::lock_guard lock(m_);
    stop_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

void ReadAhead::work() {
  std::int64_t from = position_;
  try {
    for (const auto& run : runs_) {
      {
        std::unique_lock lock(m_);
        cv_.wait(lock, [this] { return stop_ || ready_.empty() || ready_measurements_ < max_measurements_; });
        if (stop_) return;
      }
      const auto t = std::chrono::steady_clock::now();
      RunBatch b = reader_.read(bench_id_, run, from);
      const double took = seconds_since(t);
      from = run.ended_event;
      {
        std::lock_guard lock(m_);
        read_s_ += took;
        ready_measurements_ += b.measurement_count;
        ready_.push_back(std::move(b));
      }
      cv_.notify_all();
    }
  } catch (...) {
    std::lock_guard lock(m_);
    error_ = std::current_exception();
  }
  {
    std::lock_guard lock(m_);
    done_ = true;
  }
  cv_.notify_all();
}

std::optional<RunBatch> ReadAhead::next() {
  const auto t = std::chrono::steady_clock::now();
  std::unique_lock lock(m_);
  cv_.wait(lock, [this] { return !ready_.empty() || done_; });
  wait_s_ += seconds_since(t);
  if (ready_.empty()) {
    if (error_) std::rethrow_exception(error_);
    return std::nullopt;
  }
  RunBatch b = std::move(ready_.front());
  ready_.pop_front();
  ready_measurements_ -= b.measurement_count;
  lock.unlock();
  cv_.notify_all();
  return b;
}

double ReadAhead::read_seconds() {
  std::lock_guard lock(m_);
  return read_s_;
}

}  // namespace colorlab::fleet
