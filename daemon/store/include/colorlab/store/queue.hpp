#pragma once
// The night's queue as stored: items waiting their turn (campaign, validated parameters, on-failure
// policy), the execution each one became, and whether the queue runs. Every change is one
// transaction that also appends to the event log (topic `queue`), so the rows and the log never
// disagree after a crash. Queued items are numbered 1..N without gaps; an item that leaves the
// queue (started, removed) loses its position.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/store/store.hpp"

namespace colorlab::store {

enum class QueueItemState { queued, running, done, failed, skipped, removed };
enum class OnFailure { stop, go_on };  // "stop" | "continue" on the wire

std::string_view to_string(QueueItemState s);
std::optional<QueueItemState> queue_item_state_from_string(std::string_view s);
std::string_view to_string(OnFailure f);
// "stop" | "continue"; throws Error{bad_parameter} naming the allowed values.
OnFailure on_failure_from_string(std::string_view s);

struct QueueItem {
  std::string id;  // UUIDv7
  std::optional<std::int64_t> position;  // 1-based, while queued
  std::string campaign;
  nlohmann::json params;
  OnFailure on_failure = OnFailure::stop;
  QueueItemState state = QueueItemState::queued;
  std::optional<std::string> execution_id;
  std::string reason;
  std::string created_at, updated_at;
  std::optional<std::string> started_at, finished_at;
  nlohmann::json to_json() const;
};

struct NewQueueItem {
  std::string campaign;
  nlohmann::json params;  // already validated against the script's declaration
  OnFailure on_failure = OnFailure::stop;
  std::optional<std::string> idempotency_key;
};

struct QueueStatus {
  bool started = false;
  bool halted = false;  // stopped because an item failed with on_failure = stop
  std::string reason;
  std::string updated_at;
};

// The idempotency key under which the queue starts an item's execution: a daemon killed between
// starting the execution and recording it on the item finds it again (adopt_started_executions)
// instead of starting it twice.
std::string queue_execution_key(const std::string& item_id);

class QueueStore {
 public:
  explicit QueueStore(Store& store) : store_(store) {}

  struct Enqueued {
    QueueItem item;
    bool created = false;  // false: the idempotency key was used before; this is that item
  };
  // Appends at the end of the queue.
  Enqueued enqueue(const NewQueueItem& item);
  std::optional<QueueItem> item(const std::string& id);
  // The running item (if any), then the queued ones by position.
  std::vector<QueueItem> pending();
  std::optional<QueueItem> next_queued();
  // Items that have left the queue (done, failed, skipped, removed), most recently changed first.
  std::vector<QueueItem> history(unsigned limit);

  // Only a queued item can be removed or moved: Error{not_found} for an unknown id,
  // Error{conflict} for one that has left the queue, Error{bad_parameter} for a position outside 1..N.
  QueueItem remove(const std::string& id);
  QueueItem move(const std::string& id, std::int64_t position);

  // The item became this execution (queued → running).
  QueueItem mark_running(const std::string& id, const std::string& execution_id);
  // The item ended: done, failed or skipped, with the reason.
  QueueItem finish(const std::string& id, QueueItemState state, const std::string& reason);
  // Queued items whose execution exists already (see queue_execution_key) become running. Returns how many.
  int adopt_started_executions();

  QueueStatus status();
  void set_status(bool started, bool halted, const std::string& reason);

 private:
  QueueItem read(Statement& st);
  QueueItem require(const std::string& id);
  void renumber();
  void event(const std::string& change, const QueueItem& item);

  Store& store_;
};

}  // namespace colorlab::store
