#include "colorlab/daemon/step_committer.hpp"

#include "colorlab/daemon/worker_pool.hpp"

namespace colorlab::daemon {

StepCommitter::StepCommitter(boost::asio::any_io_executor io, const std::filesystem::path& database_path)
    : store_(std::make_unique<store::Store>(database_path, store::Store::SecondWriter{})),
      thread_(std::make_unique<WorkerPool>(std::move(io), WorkerPoolOptions{1, 0, {}, 0, "committer"})) {}

StepCommitter::~StepCommitter() { shutdown(); }

boost::asio::awaitable<void> StepCommitter::commit(store::ExecutionRecord execution, store::StepRecord step) {
  // The job owns its copies: the io thread goes on while it runs.
  auto job = [store = store_.get(), execution = std::move(execution), step = std::move(step)]() -> nlohmann::json {
    store->commit_step(execution, step);
    return nullptr;
  };
  co_await thread_->run("a step's commit", std::move(job), Admission::always);
}

void StepCommitter::shutdown() {
  if (thread_) thread_->shutdown();
}

}  // namespace colorlab::daemon
