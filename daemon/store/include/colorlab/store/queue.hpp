#pragma once
// The night's queue as stored: items waiting their turn (campaign, validated parameters, on-failure
// policy), the execution each one became, and whether the queue runs. Every change is one
// transaction that also appends to the event log (topic `queue`), so the rows and the log never
// disagree after a crash. Queued items are numbered 1..N without gaps; an item that leaves the
// queue (started, removed) loses its position.
//
// An item may take an earlier item's run as a parameter: its params hold {"$run_of": "<item id>"}
// there (kept as param_refs: parameter -> item id). The referenced item must be queued before it
// (enqueue and move refuse otherwise, QueueConflict); when the item comes up the reference is
// replaced by the run id, written into the item (resolve) before its execution starts. Items of a
// sequence are queued together as a group (group_id, step).
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/store/store.hpp"

namespace colorlab::store {

enum class QueueItemState {
  queued,
  running,
  done,
  failed,
  skipped,
  removed
};
enum class OnFailure {
  stop,
  go_on
};  // "stop" | "continue" on the wire

std::string_view to_string(QueueItemState s);
std::optional<QueueItemState> queue_item_state_from_string(std::string_view s);
std::string_view to_string(OnFailure f);

// A refusal the API answers with 409 and its own problem code (e.g. "queue-reference-order").
class QueueConflict : public Error {
 public:
  QueueConflict(std::string code, std::string message, std::string hint)
      : Error(ErrorClass::conflict, std::move(message), std::move(hint)), code_(std::move(code)) {}
  const std::string& code() const noexcept { return code_; }

 private:
  std::string code_;
};

// {"$run_of": "<item id>"} in a queued item's params: the run that item became.
inline constexpr const char* kRunOfKey = "$run_of";
// The parameters of `params` that are such references (parameter -> item id). Throws
// Error{bad_parameter} for a malformed one ({"$run_of": 3}, or other keys beside it).
std::map<std::string, std::string> run_of_references(const nlohmann::json& params);
// "stop" | "continue"; throws Error{bad_parameter} naming the allowed values.
OnFailure on_failure_from_string(std::string_view s);

struct QueueItem {
  std::string id;                        // UUIDv7
  std::optional<std::int64_t> position;  // 1-based, while queued
  std::string campaign;
  nlohmann::json params;
  OnFailure on_failure = OnFailure::stop;
  QueueItemState state = QueueItemState::queued;
  std::optional<std::string> execution_id;
  std::string reason;
  std::string created_at, updated_at;
  std::optional<std::string> started_at, finished_at;
  std::map<std::string, std::string> param_refs;  // parameter -> the item whose run it takes
  std::optional<std::string> group_id, step;      // queued as part of a sequence
  // True while a reference in params is still {"$run_of": ...} (not yet resolved to a run id).
  bool has_unresolved_references() const;
  nlohmann::json to_json() const;
};

struct NewQueueItem {
  std::string campaign;
  nlohmann::json params;  // already validated against the script's declaration
  OnFailure on_failure = OnFailure::stop;
  std::optional<std::string> idempotency_key;
  // params may hold {"$run_of": id}: the parameters that do, with the item ids (run_of_references).
  std::map<std::string, std::string> param_refs;
  std::optional<std::string> id;  // preassigned (a group's items reference each other); else a new UUIDv7
  std::optional<std::string> group_id, step;
};

struct QueueGroup {
  std::string id;
  std::string sequence;
  nlohmann::json options = nlohmann::json::object();
  std::string created_at;
  std::vector<QueueItem> items;  // in the order they were queued
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
  // Appends at the end of the queue. A referenced item must exist and be queued, running or done
  // (QueueConflict "queue-reference-unknown" / "queue-reference-ended" otherwise).
  Enqueued enqueue(const NewQueueItem& item);
  // A sequence's items appended in one transaction as group `group_id`; each may reference the ones
  // before it. A retry whose first item's idempotency key was used before returns that group.
  struct EnqueuedGroup {
    QueueGroup group;
    bool created = false;
  };
  EnqueuedGroup enqueue_group(const std::string& group_id, const std::string& sequence, const nlohmann::json& options,
                              const std::vector<NewQueueItem>& items);
  std::optional<QueueGroup> group(const std::string& id);
  // The item's references written in: params get the run ids (event "resolved").
  QueueItem resolve(const std::string& id, const nlohmann::json& params);
  std::optional<QueueItem> item(const std::string& id);
  // The running item (if any), then the queued ones by position.
  std::vector<QueueItem> pending();
  std::optional<QueueItem> next_queued();
  // Items that have left the queue (done, failed, skipped, removed), most recently changed first.
  std::vector<QueueItem> history(unsigned limit);

  // Only a queued item can be removed or moved: Error{not_found} for an unknown id,
  // Error{conflict} for one that has left the queue, Error{bad_parameter} for a position outside 1..N.
  // A move that would put an item before an item whose run it takes (or after one that takes its run)
  // is refused: QueueConflict "queue-reference-order".
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
  Enqueued insert(const NewQueueItem& item);  // inside the caller's transaction
  void renumber();
  void check_order_after_move(const QueueItem& moved, std::int64_t position);
  void event(const std::string& change, const QueueItem& item);

  Store& store_;
};

}  // namespace colorlab::store
