#pragma once
// Campaign executions (SiLA's observable commands): a POST validates the parameters against the
// script's declaration, stores the run with the script's exact text, and returns at once; the
// script runs as a coroutine on the daemon's executor through the campaign engine. Executions
// left unfinished by a crash, a power cut or a shutdown are resumed at start-up by replay; one whose
// step keeps killing the daemon is suspended by the crash-loop guard (crash_loop.hpp) and retried
// after a bounded back-off. Pause, resume and abort land at the engine's next safe point.
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <boost/asio/awaitable.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/campaigns/catalogue.hpp"
#include "colorlab/campaigns/control.hpp"
#include "colorlab/campaigns/lab.hpp"
#include "colorlab/daemon/crash_loop.hpp"
#include "colorlab/store/store.hpp"

namespace colorlab::daemon {

class Notifier;
class WorkerPool;
class StepCommitter;

// A campaign start refused because the lab is in use: one set of instruments, one execution at a time.
// The API answers 409 `lab-busy` naming the execution that holds the lab (`execution_id`).
class LabBusy : public Error {
 public:
  explicit LabBusy(const store::ExecutionRecord& holder);
  const std::string& execution_id() const noexcept { return execution_id_; }

 private:
  std::string execution_id_;
};

struct ExecutionOptions {
  CrashLoopPolicy crash_loop;          // includes max_resume_attempts
  std::filesystem::path state_dir;     // where runs are stored (a dry run checks its free space)
  Notifier* notifier = nullptr;        // told of suspensions, crash loops and failures; none: nobody is
  WorkerPool* workers = nullptr;       // where scripts' analyses (fits) and dry runs compute; none: inline
  StepCommitter* committer = nullptr;  // where steps before a live call are made durable; none: the io thread
};

class Executions {
 public:
  Executions(boost::asio::io_context& io, store::Store& store, campaigns::ScriptCatalogue& catalogue,
             const campaigns::InstrumentSet& instruments, campaigns::Lab& lab, ExecutionOptions options,
             std::function<void(const std::string&)> status_text = {});
  ~Executions();

  // Validates, records and launches. Throws Error{bad_parameter|not_found} before anything starts, and
  // LabBusy while another execution is unfinished (waiting, running, paused or suspended: it holds the
  // instruments, the lamps and whatever the operator placed; the night queue waits for it likewise).
  // A retried POST with the same Idempotency-Key gets its execution back, also while it holds the lab.
  store::ExecutionRecord start(const std::string& campaign, const nlohmann::json& params,
                               const std::optional<std::string>& idempotency_key);
  // The campaign run against a lab that moves nothing (campaigns/dry_run.hpp): limits, instruments,
  // disk, operator actions and the estimated duration from this lab's learned call timings.
  // Throws Error{bad_parameter|not_found} for an unknown campaign or invalid parameters, and
  // WorkerPoolFull while the worker pool's queue is full. Runs on the io thread, which it leaves
  // while the script's analyses run on the worker pool.
  boost::asio::awaitable<nlohmann::json> dry_run(const std::string& campaign, const nlohmann::json& params);
  // At start-up: every execution a previous process left running or suspended continues, except one
  // the crash-loop guard suspends (or, its retries spent, ends) and one waiting out the guard's back-off.
  void resume_unfinished();
  store::ExecutionRecord pause(const std::string& id);
  // Throws LabBusy while another execution runs.
  store::ExecutionRecord resume(const std::string& id);
  store::ExecutionRecord abort(const std::string& id);
  // SIGTERM: running executions stop at their next safe point as `suspended` (resumed at the next
  // start); `done` runs when all have stopped.
  void shutdown(std::function<void()> done);

  std::size_t running() const { return active_.size(); }
  // The condition a running execution is waiting out, if any (also when the disk could not store it).
  std::optional<std::string> live_suspension(const std::string& id) const;

 private:
  struct Active;
  void launch(store::ExecutionRecord record, std::shared_ptr<const campaigns::CampaignScript> script,
              nlohmann::json params, bool resumed, bool accept_units = false, nlohmann::json resumed_by = nullptr);
  void relaunch(const store::ExecutionRecord& record, bool accept_units, nlohmann::json resumed_by = nullptr);
  // The guard has tripped for this execution after `attempts` resumes in a row without a commit.
  void crash_loop(const store::ExecutionRecord& record, int attempts);
  // Retries a crash-loop suspension by itself once `seconds` have passed (unless resumed or aborted first).
  void arm_backoff(const std::string& id, double seconds);
  void cancel_backoff(const std::string& id);
  void notify(const std::string& event, const store::ExecutionRecord& record, const std::string& reason,
              const nlohmann::json& problem, const nlohmann::json& suspension = nullptr);
  store::ExecutionRecord require(const std::string& id);
  void maybe_done();

  boost::asio::io_context& io_;
  store::Store& store_;
  campaigns::ScriptCatalogue& catalogue_;
  const campaigns::InstrumentSet& instruments_;
  campaigns::Lab& lab_;
  ExecutionOptions options_;
  std::function<void(const std::string&)> status_text_;
  std::map<std::string, std::shared_ptr<Active>> active_;
  std::map<std::string, std::shared_ptr<boost::asio::steady_timer>> backoffs_;  // crash-loop suspensions waiting
  std::function<void()> on_all_stopped_;
  bool shutting_down_ = false;
};

}  // namespace colorlab::daemon
