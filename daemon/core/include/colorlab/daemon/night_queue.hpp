#pragma once
// The night's queue (issue 9; Bluesky's queue server, daemon-design-notes §2.4): executions that
// wait their turn, stored so that the queue outlives the daemon. While the queue is started it
// starts the next item whenever no execution is unfinished (a paused or suspended run holds the
// lab as much as a running one), follows the item's execution through the store to its end, and
// applies the item's on-failure policy. It starts each execution under an idempotency key made
// from the item's id, so a daemon killed at any moment neither loses an item nor starts one twice:
// after a restart the engine resumes the running item's execution and the queue simply follows it.
#include <chrono>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/campaigns/catalogue.hpp"
#include "colorlab/campaigns/lab.hpp"
#include "colorlab/daemon/executions.hpp"
#include "colorlab/store/queue.hpp"
#include "colorlab/store/store.hpp"

namespace colorlab::daemon {

struct QueueOptions {
  bool autostart = false;  // [queue] autostart: start the queue with the daemon
  // How often the store is looked at for the running item's end. Executions end at most a few
  // times a night; a quarter second costs one indexed read and keeps the lab idle only briefly.
  std::chrono::milliseconds poll_interval{250};
};

class NightQueue {
 public:
  NightQueue(boost::asio::io_context& io, store::Store& store, Executions& executions,
             campaigns::ScriptCatalogue& catalogue, const campaigns::Lab& lab, QueueOptions options);

  // At daemon start, after Executions::resume_unfinished: adopts executions a killed daemon
  // started but did not record, applies autostart, and begins following the lab.
  void start_up();
  // SIGTERM: starts nothing more. The queue stays started in the store, so the next daemon goes on.
  void shutdown();

  // Validated exactly as Executions::start validates (400/404 before anything is stored). A parameter
  // {"$run_of": "<item id>"} takes that earlier item's run id when this item comes up (409
  // queue-reference-unknown / queue-reference-ended for an item that does not exist or never will run).
  store::QueueStore::Enqueued enqueue(const std::string& campaign, const nlohmann::json& params,
                                      store::OnFailure on_failure, const std::optional<std::string>& idempotency_key);
  // A catalogue sequence's steps queued at once as one group, each step validated as enqueue does and
  // its reference given as {"$run_of": <the referenced step's item>}; `small` applies the sequence's
  // small overrides, then `overrides` ({step: {key: value}}). A retry with the same Idempotency-Key
  // returns the group it queued.
  store::QueueStore::EnqueuedGroup enqueue_sequence(const std::string& name, bool small, const nlohmann::json& overrides,
                                                    store::OnFailure on_failure,
                                                    const std::optional<std::string>& idempotency_key);
  // {id, sequence, options, created_at, state: queued|running|done|failed, items (each with run_id),
  //  runs: {step: run id} and run_ids (in order) of its done items, links.report once it has ended}
  nlohmann::json describe_group(const store::QueueGroup& group);
  nlohmann::json group(const std::string& id);
  // The run ids of a group's done items, in order, and whether nothing of it is queued or running.
  std::pair<std::vector<std::string>, bool> group_runs(const std::string& id);
  // A catalogue sequence by this name, and no campaign by it.
  bool is_sequence(const std::string& name);
  static bool group_ended(const store::QueueGroup& group);
  store::QueueItem remove(const std::string& id);
  store::QueueItem move(const std::string& id, std::int64_t position);
  store::QueueItem item(const std::string& id);
  // start: runs items from the next queued one on (clears a halt). stop: starts no further item;
  // the running one goes on to its end.
  void start();
  void stop();

  // {state: running|stopping|stopped, reason, halted, autostart, current, waiting_for, items, history}
  nlohmann::json describe(unsigned history_limit);

 private:
  void schedule();
  void poke();
  void step();
  // Ends the running item once its execution has ended; true while it still holds the queue.
  bool follow_running();
  void start_next();
  void after_failure(const store::QueueItem& item);
  std::optional<nlohmann::json> resolve_references(const store::QueueItem& item, std::string& why);

  boost::asio::io_context& io_;
  store::Store& store_;
  store::QueueStore queue_;
  Executions& executions_;
  campaigns::ScriptCatalogue& catalogue_;
  const campaigns::Lab& lab_;
  QueueOptions options_;
  boost::asio::steady_timer timer_;
  std::optional<std::string> waiting_for_;  // an execution not from the queue that holds the lab
  bool stopped_ = true;
};

}  // namespace colorlab::daemon
