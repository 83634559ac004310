#include "colorlab/daemon/night_queue.hpp"

#include <algorithm>

#include <boost/asio/post.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/core/ids.hpp"
#include "colorlab/core/log.hpp"
#include "colorlab/daemon/campaign_request.hpp"
#include "colorlab/protocol/api.hpp"
#include "colorlab/protocol/states.hpp"

namespace colorlab::daemon {

namespace asio = boost::asio;
using nlohmann::json;
using protocol::ExecutionStatus;
using store::QueueItem;
using store::QueueItemState;

namespace {

// The whole id: a UUIDv7's leading digits are its timestamp, alike for items queued together.
std::string describe_item(const QueueItem& item) { return "item " + item.id + " (" + item.campaign + ")"; }

}  // namespace

NightQueue::NightQueue(asio::io_context& io, store::Store& store, Executions& executions,
                       campaigns::ScriptCatalogue& catalogue, const campaigns::Lab& lab, QueueOptions options)
    : io_(io),
      store_(store),
      queue_(store),
      executions_(executions),
      catalogue_(catalogue),
      lab_(lab),
      options_(options),
      timer_(io) {}

void NightQueue::start_up() {
  int adopted = queue_.adopt_started_executions();
  if (adopted > 0) log::info("queue", std::to_string(adopted) + " item(s) found already started by the previous process");
  auto status = queue_.status();
  if (!status.started && options_.autostart) {
    // A queue halted by a failed item waits for a person even with autostart: starting it again
    // unattended would defeat the item's on_failure = stop.
    if (status.halted) {
      log::warning("queue", "not started despite [queue] autostart: " + status.reason + " (colorlab queue start)");
    } else {
      queue_.set_status(true, false, "started with colorlabd ([queue] autostart)");
    }
  }
  auto pending = queue_.pending();
  log::info("queue", std::string(queue_.status().started ? "started" : "stopped") + ", " +
                         std::to_string(pending.size()) + " item(s) pending");
  stopped_ = false;
  poke();
  schedule();
}

void NightQueue::shutdown() {
  stopped_ = true;
  timer_.cancel();
}

void NightQueue::schedule() {
  if (stopped_) return;
  timer_.expires_after(options_.poll_interval);
  timer_.async_wait([this](boost::system::error_code ec) {
    if (ec || stopped_) return;
    step();
    schedule();
  });
}

// A change a client made is acted on at once rather than at the next poll.
void NightQueue::poke() {
  asio::post(io_, [this] {
    if (!stopped_) step();
  });
}

void NightQueue::step() {
  try {
    if (follow_running()) return;
    start_next();
  } catch (const Error& e) {
    // Storage trouble: nothing was half done (every change is one transaction); look again later.
    log::warning("queue", std::string("cannot advance the queue: ") + e.what());
  }
}

bool NightQueue::follow_running() {
  bool holds = false;
  for (const auto& item : queue_.pending()) {
    if (item.state != QueueItemState::running) break;  // running items come first
    std::optional<store::ExecutionRecord> execution;
    if (item.execution_id) execution = store_.execution(*item.execution_id);
    if (!execution) {
      auto failed = queue_.finish(item.id, QueueItemState::failed, "its execution is missing from the store");
      after_failure(failed);
      continue;
    }
    if (!protocol::is_terminal(execution->status)) {
      holds = true;  // running, or paused / suspended: it holds the queue until it ends
      continue;
    }
    if (execution->status == ExecutionStatus::finished_ok) {
      queue_.finish(item.id, QueueItemState::done, "");
      log::info("queue", describe_item(item) + " done");
      continue;
    }
    std::string why = "execution " + execution->id + " " + std::string(protocol::to_string(execution->status)) +
                      (execution->reason.empty() ? "" : ": " + execution->reason);
    auto failed = queue_.finish(item.id, QueueItemState::failed, why);
    log::warning("queue", describe_item(item) + " failed: " + why);
    after_failure(failed);
  }
  return holds;
}

void NightQueue::after_failure(const QueueItem& item) {
  if (item.on_failure != store::OnFailure::stop) return;
  std::string why = describe_item(item) + " " + std::string(store::to_string(item.state)) + " (" + item.reason +
                    "); its on_failure is stop";
  queue_.set_status(false, true, why);
  log::warning("queue", "halted: " + why + "; colorlab queue start goes on with the next item");
}

void NightQueue::start_next() {
  if (!queue_.status().started) return;
  // The lab has one set of instruments: any unfinished execution, from the queue or not, holds it.
  auto unfinished = store_.unfinished_executions();
  if (!unfinished.empty()) {
    waiting_for_ = unfinished.front().id;
    return;
  }
  waiting_for_.reset();
  // An item whose execution a killed daemon started but never recorded is that execution's, not a new one.
  if (queue_.adopt_started_executions() > 0) return;
  auto next = queue_.next_queued();
  if (!next) return;
  if (next->has_unresolved_references()) {
    std::string why;
    auto resolved = resolve_references(*next, why);
    if (!resolved) {
      auto skipped = queue_.finish(next->id, QueueItemState::skipped, why);
      log::warning("queue", describe_item(*next) + " skipped: " + why);
      after_failure(skipped);
      return;
    }
    // Written before the execution starts: a daemon killed in between starts the item with these run ids.
    next = queue_.resolve(next->id, *resolved);
  }
  try {
    auto execution = executions_.start(next->campaign, next->params, store::queue_execution_key(next->id));
    queue_.mark_running(next->id, execution.id);
    log::info("queue", describe_item(*next) + " started as execution " + execution.id);
  } catch (const LabBusy& busy) {
    // Not the item's fault: it waits, as above (the check there and the refusal agree today; this keeps a
    // disagreement from skipping the item and halting the night).
    waiting_for_ = busy.execution_id();
  } catch (const Error& e) {
    if (e.cls() == ErrorClass::io_error) throw;  // the disk, not the item: try again at the next poll
    // The script was removed or edited since the item was queued, or an instrument it needs is gone.
    std::string why = std::string("could not start: ") + e.what() + (e.hint().empty() ? "" : " (" + e.hint() + ")");
    auto skipped = queue_.finish(next->id, QueueItemState::skipped, why);
    log::warning("queue", describe_item(*next) + " skipped: " + why);
    after_failure(skipped);
  }
}

// The item's params with each {"$run_of": id} replaced by that item's run id; nullopt (and why) when a
// referenced item has no run to give: it failed, was skipped or removed (or, impossibly, has not run yet).
std::optional<json> NightQueue::resolve_references(const QueueItem& item, std::string& why) {
  json params = item.params;
  for (const auto& [param, ref] : item.param_refs) {
    if (!params.contains(param) || !params[param].is_object()) continue;  // resolved before
    auto target = queue_.item(ref);
    std::string what = "its parameter '" + param + "' takes the run of item " + ref;
    if (!target) {
      why = what + ", which is gone from the store";
      return std::nullopt;
    }
    what += " (" + target->campaign + ")";
    std::optional<store::ExecutionRecord> execution;
    if (target->state == QueueItemState::done && target->execution_id) execution = store_.execution(*target->execution_id);
    if (!execution) {
      why = what + ", which " +
            (target->state == QueueItemState::done ? std::string("has no execution in the store")
                                                   : std::string(store::to_string(target->state))) +
            (target->reason.empty() ? "" : " (" + target->reason + ")");
      return std::nullopt;
    }
    params[param] = execution->run_id;
  }
  return params;
}

namespace {

// Validates as Executions::start would, with each {"$run_of": id} standing in as a string; returns the
// validated params with the references put back.
json validated_with_references(campaigns::ScriptCatalogue& catalogue, const campaigns::Lab& lab,
                               const std::string& campaign, const json& params,
                               const std::map<std::string, std::string>& refs) {
  json standing_in = params;
  for (const auto& [param, ref] : refs) standing_in[param] = "$run_of:" + ref;
  auto request = validate_campaign_request(catalogue, lab, campaign, standing_in);
  json out = request.params;
  for (const auto& [param, ref] : refs) {
    if (!out.contains(param) || !out[param].is_string()) {
      throw Error(ErrorClass::bad_parameter,
                  "parameter '" + param + "' of " + campaign + " cannot take a run: it is not a string parameter",
                  "only a run-id (string) parameter takes {\"$run_of\": ...}");
    }
    out[param] = json{{store::kRunOfKey, ref}};
  }
  return out;
}

}  // namespace

store::QueueStore::Enqueued NightQueue::enqueue(const std::string& campaign, const json& params,
                                                store::OnFailure on_failure,
                                                const std::optional<std::string>& idempotency_key) {
  auto refs = store::run_of_references(params);
  store::NewQueueItem n{campaign, validated_with_references(catalogue_, lab_, campaign, params, refs), on_failure,
                        idempotency_key};
  n.param_refs = refs;
  auto enqueued = queue_.enqueue(n);
  if (enqueued.created) poke();
  return enqueued;
}

store::QueueStore::EnqueuedGroup NightQueue::enqueue_sequence(const std::string& name, bool small,
                                                              const json& overrides, store::OnFailure on_failure,
                                                              const std::optional<std::string>& idempotency_key) {
  catalogue_.refresh();
  auto sequence = catalogue_.find_sequence(name);
  if (!sequence) throw Error(ErrorClass::not_found, "no sequence named '" + name + "'", "colorlab campaigns lists them");
  std::map<std::string, std::string> ids;  // step -> its item's id, for the steps after it
  std::vector<store::NewQueueItem> items;
  for (const auto& step : sequence->expand(small, overrides)) {
    std::string id = new_uuid_v7();
    json params = step.params;
    std::map<std::string, std::string> refs;
    if (step.reference_param) {
      refs[*step.reference_param] = ids.at(*step.reference_step);
      params[*step.reference_param] = json{{store::kRunOfKey, refs[*step.reference_param]}};
    }
    store::NewQueueItem n;
    try {
      n = {step.campaign, validated_with_references(catalogue_, lab_, step.campaign, params, refs), on_failure,
           idempotency_key ? std::optional<std::string>(*idempotency_key + "/" + step.name) : std::nullopt};
    } catch (const Error& e) {
      ErrorInfo info = e.info();
      info.message = "step '" + step.name + "' (" + step.campaign + ") of sequence " + name + ": " + info.message;
      throw Error(info);
    }
    n.param_refs = refs;
    n.id = id;
    n.step = step.name;
    ids[step.name] = id;
    items.push_back(std::move(n));
  }
  json options{
      {"small", small},
      {"overrides", overrides.is_null() ? json::object() : overrides},
      {"on_failure", store::to_string(on_failure)},
  };
  auto enqueued = queue_.enqueue_group(new_uuid_v7(), name, options, items);
  if (enqueued.created) poke();
  return enqueued;
}

json NightQueue::describe_group(const store::QueueGroup& group) {
  json items = json::array();
  json runs = json::object();
  json run_ids = json::array();
  bool all_done = !group.items.empty(), any_bad = false, any_running = false;
  for (const auto& item : group.items) {
    json j = item.to_json();
    std::optional<store::ExecutionRecord> execution;
    if (item.execution_id) execution = store_.execution(*item.execution_id);
    j["run_id"] = execution ? json(execution->run_id) : json(nullptr);
    if (execution && item.state == QueueItemState::done) {
      runs[item.step.value_or(item.id)] = execution->run_id;
      run_ids.push_back(execution->run_id);
    }
    all_done = all_done && item.state == QueueItemState::done;
    any_bad = any_bad || item.state == QueueItemState::failed || item.state == QueueItemState::skipped ||
              item.state == QueueItemState::removed;
    any_running = any_running || item.state == QueueItemState::running;
    items.push_back(j);
  }
  std::string state = all_done ? "done" : any_bad   ? "failed"
                                      : any_running ? "running"
                                                    : "queued";
  json described{
      {"id", group.id},
      {"sequence", group.sequence},
      {"options", group.options},
      {"created_at", group.created_at},
      {"state", state},
      {"items", items},
      {"runs", runs},
      {"run_ids", run_ids},
  };
  // The study's report, of the runs it finished, once nothing of it is left to run.
  if (group_ended(group) && !run_ids.empty())
    described["links"] = {{"report", std::string(protocol::kPrefix) + "/queue/groups/" + group.id + "/report"}};
  return described;
}

bool NightQueue::group_ended(const store::QueueGroup& group) {
  return std::none_of(group.items.begin(), group.items.end(), [](const QueueItem& item) {
    return item.state == QueueItemState::queued || item.state == QueueItemState::running;
  });
}

std::pair<std::vector<std::string>, bool> NightQueue::group_runs(const std::string& id) {
  auto g = queue_.group(id);
  if (!g) throw Error(ErrorClass::not_found, "no queue group with id '" + id + "'", "a sequence queued returns its group's id");
  std::vector<std::string> run_ids;
  const json described = describe_group(*g);  // held: a range-for over a temporary's member would dangle
  for (const auto& run : described["run_ids"]) run_ids.push_back(run.get<std::string>());
  return {run_ids, group_ended(*g)};
}

json NightQueue::group(const std::string& id) {
  auto g = queue_.group(id);
  if (!g) throw Error(ErrorClass::not_found, "no queue group with id '" + id + "'", "a sequence queued returns its group's id");
  return describe_group(*g);
}

bool NightQueue::is_sequence(const std::string& name) {
  catalogue_.refresh();
  return catalogue_.find_sequence(name) && !catalogue_.find(name);
}

QueueItem NightQueue::remove(const std::string& id) { return queue_.remove(id); }

QueueItem NightQueue::move(const std::string& id, std::int64_t position) { return queue_.move(id, position); }

QueueItem NightQueue::item(const std::string& id) {
  auto q = queue_.item(id);
  if (!q) throw Error(ErrorClass::not_found, "no queue item with id '" + id + "'", "colorlab queue list shows the queue");
  return *q;
}

void NightQueue::start() {
  auto status = queue_.status();
  if (!status.started) queue_.set_status(true, false, "started by a client");
  poke();
}

void NightQueue::stop() {
  auto status = queue_.status();
  if (status.started) queue_.set_status(false, false, "stopped by a client");
}

json NightQueue::describe(unsigned history_limit) {
  auto status = queue_.status();
  json items = json::array();
  json current = nullptr;
  for (const auto& item : queue_.pending()) {
    json j = item.to_json();
    if (item.state == QueueItemState::running && current.is_null()) {
      auto execution = item.execution_id ? store_.execution(*item.execution_id) : std::nullopt;
      j["execution_status"] = execution ? json(protocol::to_string(execution->status)) : json(nullptr);
      // What holds the queue: a suspended run says why and, from the crash-loop guard, until when.
      if (execution && !execution->reason.empty()) j["execution_reason"] = execution->reason;
      if (execution && !execution->suspension.is_null()) j["execution_suspension"] = execution->suspension;
      current = j;
    }
    items.push_back(j);
  }
  json history = json::array();
  for (const auto& item : queue_.history(history_limit)) history.push_back(item.to_json());
  std::string state = status.started ? "running" : current.is_null() ? "stopped"
                                                                     : "stopping";
  return {{"state", state},
          {"reason", status.reason},
          {"halted", status.halted},
          {"autostart", options_.autostart},
          {"updated_at", status.updated_at},
          {"current", current},
          {"waiting_for", status.started && current.is_null() && waiting_for_ ? json(*waiting_for_) : json(nullptr)},
          {"items", items},
          {"history", history}};
}

}  // namespace colorlab::daemon
