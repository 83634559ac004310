#pragma once
// A cycle's runs read from the bench's SQLite on a thread of its own while the caller ships the ones before them:
// the bench's side (SQLite, COPY text, the bench's digest) overlaps central's COPY, digest and commit instead of
// adding to them (docs/PERFORMANCE.md, "Shipping a backlog"). The runs come out in order, each read from the
// position after the one before it, each in its own read transaction, as BenchReader::read gives them.
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <filesystem>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "colorlab/fleet/bench_reader.hpp"

namespace colorlab::fleet {

class ReadAhead {
 public:
  // Holds at most about `max_measurements` measurements read and not yet taken (always at least one run), so
  // memory stays near one transaction's worth however long the backlog.
  ReadAhead(const std::filesystem::path& database, std::string bench_id, std::vector<EndedRun> runs,
            std::int64_t position, std::int64_t max_measurements);
  ~ReadAhead();
  ReadAhead(const ReadAhead&) = delete;
  ReadAhead& operator=(const ReadAhead&) = delete;

  // The next run, or nullopt after the last; rethrows what stopped the reader (its runs before that come first).
  std::optional<RunBatch> next();
  // The reader thread's time in BenchReader::read so far, and the caller's time waiting in next().
  double read_seconds();
  double wait_seconds() const { return wait_s_; }

 private:
  void work();

  BenchReader reader_;  // opened by the constructor (its errors are the caller's), then used by the thread only
  const std::string bench_id_;
  const std::vector<EndedRun> runs_;
  const std::int64_t position_;
  const std::int64_t max_measurements_;
  std::mutex m_;
  std::condition_variable cv_;
  std::deque<RunBatch> ready_;
  std::int64_t ready_measurements_ = 0;
  bool done_ = false, stop_ = false;
  std::exception_ptr error_;
  double read_s_ = 0, wait_s_ = 0;
  std::thread thread_;
};

}  // namespace colorlab::fleet
