#pragma once
// Commits campaign steps off colorlabd's io thread (issue 27). A step's commit is one transaction with
// synchronous=FULL — an fsync of the WAL, now and then a checkpoint's writes — which on a busy disk takes
// far longer than the io thread may stall: every `main` route, the operator's answers and the watchdog's
// ping wait behind it. Here it runs on a thread of its own, through a second writer connection
// (store::Store::SecondWriter), and the execution that asked resumes on the io thread once it is durable.
//
// What does not change: a step is durable before the execution's next lab call (the engine awaits the
// commit before it moves anything), the step's progress event is in the same transaction (no event
// announces what is not on disk), and one execution's steps commit in order (it waits for each). Steps of
// two executions are ordered by SQLite's write lock, so the event log's seq stays the commit order.
//
// The WAL's checkpoints run here too: the io thread's own connection (the daemon's Store) hands them over
// (store::Store::hand_wal_checkpoints_to), so that the copy of the WAL into the database and its fsync, which
// SQLite runs inside whichever COMMIT crosses the threshold, never hold up the io thread. A checkpoint is a job of
// this thread like a step's commit: a step queued behind one waits for it (the committer's own commits ran theirs
// inline before, so its steps waited as long).
//
// Threads and locks: one thread (a WorkerPool of one, its queue unbounded: each execution waits for its
// own step, so no more than the executions running are ever queued, and at most one checkpoint waits). The
// connection is used on that thread only; checkpoint_queued_ is the one flag both threads touch.
#include <atomic>
#include <filesystem>
#include <memory>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/awaitable.hpp>

#include "colorlab/store/store.hpp"

namespace colorlab::daemon {

class WorkerPool;

class StepCommitter {
 public:
  // Opens the second writer's connection to the database a Store has already opened. With `io_thread_store`
  // (that Store, used on the io thread), its checkpoints are handed here until shutdown(); it must outlive this,
  // and this constructor and shutdown() must run where that Store is used (the io thread), or while it is not.
  StepCommitter(boost::asio::any_io_executor io, const std::filesystem::path& database_path,
                store::Store* io_thread_store = nullptr);
  ~StepCommitter();
  StepCommitter(const StepCommitter&) = delete;
  StepCommitter& operator=(const StepCommitter&) = delete;

  // store::Store::commit_step on the committer's thread; completes on the io thread once the step is
  // durable, or throws what the store threw (Error{io_error} for a disk that refused it: nothing stored).
  boost::asio::awaitable<void> commit(store::ExecutionRecord execution, store::StepRecord step);

  // A checkpoint of the WAL on the committer's thread, soon; never blocks, and one already waiting suffices.
  void checkpoint_soon();

  // The io thread's Store checkpoints by itself again; commits still queued end with Error{aborted}; the
  // running one finishes. Then joins.
  void shutdown();

 private:
  std::unique_ptr<store::Store> store_;
  std::unique_ptr<WorkerPool> thread_;
  store::Store* io_thread_store_ = nullptr;
  std::atomic<bool> checkpoint_queued_{false};
};

}  // namespace colorlab::daemon
