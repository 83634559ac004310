#include "colorlab/daemon/step_committer.hpp"

#include "colorlab/daemon/worker_pool.hpp"

namespace colorlab::daemon {

StepCommitter::StepCommitter(boost::asio::any_io_executor io, const std::filesystem::path& database_path,
                             store::Store* io_thread_store)
    : store_(std::make_unique<store::Store>(database_path, store::Store::SecondWriter{})),
      thread_(std::make_unique<WorkerPool>(std::move(io), WorkerPoolOptions{1, 0, {}, 0, "committer"})),
      io_thread_store_(io_thread_store) {
  if (io_thread_store_) io_thread_store_->hand_wal_checkpoints_to([this] { checkpoint_soon(); });
}

StepCommitter::~StepCommitter() { shutdown(); }

boost::asio::awaitable<void> StepCommitter::commit(store::ExecutionRecord execution, store::StepRecord step) {
  // The job owns its copies: the io thread goes on while it runs.
  auto job = [store = store_.get(), execution = std::move(execution), step = std::move(step)]() -> nlohmann::json {
    store->commit_step(execution, step);
    return nullptr;
  };
  co_await thread_->run("a step's commit", std::move(job), Admission::always);
}

void StepCommitter::checkpoint_soon() {
  if (checkpoint_queued_.exchange(true)) return;
  try {
    thread_->submit(
        "a checkpoint of the WAL",
        [this]() -> nlohmann::json {
          checkpoint_queued_ = false;  // a commit from now on may ask for the next one
          store_->checkpoint_wal();
          return nullptr;
        },
        [](std::exception_ptr, nlohmann::json) {}, Admission::always);
  } catch (...) {
    checkpoint_queued_ = false;  // not queued (shutting down, or no memory): the next commit past the threshold asks again
  }
}

void StepCommitter::shutdown() {
  if (io_thread_store_) {
    io_thread_store_->hand_wal_checkpoints_to({});
    io_thread_store_ = nullptr;
  }
  if (thread_) thread_->shutdown();
}

}  // namespace colorlab::daemon
