#include "colorlab/store/queue.hpp"

#include "colorlab/core/error.hpp"
#include "colorlab/core/ids.hpp"

namespace colorlab::store {

namespace {

constexpr const char* kItemColumns =
    "id, position, campaign, params, on_failure, state, execution_id, reason, created_at, updated_at, started_at, "
    "finished_at, param_refs, group_id, step";

constexpr const char* kQueueKeyPrefix = "queue-item:";

std::optional<std::string> optional_text(Statement& st, int col) {
  if (st.is_null(col)) return std::nullopt;
  return st.text(col);
}

}  // namespace

std::string_view to_string(QueueItemState s) {
  switch (s) {
    case QueueItemState::queued: return "queued";
    case QueueItemState::running: return "running";
    case QueueItemState::done: return "done";
    case QueueItemState::failed: return "failed";
    case QueueItemState::skipped: return "skipped";
    case QueueItemState::removed: return "removed";
  }
  return "failed";
}

std::optional<QueueItemState> queue_item_state_from_string(std::string_view s) {
  for (auto state : {QueueItemState::queued, QueueItemState::running, QueueItemState::done, QueueItemState::failed,
                     QueueItemState::skipped, QueueItemState::removed}) {
    if (to_string(state) == s) return state;
  }
  return std::nullopt;
}

std::string_view to_string(OnFailure f) { return f == OnFailure::stop ? "stop" : "continue"; }

OnFailure on_failure_from_string(std::string_view s) {
  if (s == "stop") return OnFailure::stop;
  if (s == "continue") return OnFailure::go_on;
  throw Error(ErrorClass::bad_parameter, "on_failure must be \"stop\" or \"continue\", not \"" + std::string(s) + "\"",
              "stop: a failed item halts the queue until an operator starts it again; continue: the next item runs");
}

std::string queue_execution_key(const std::string& item_id) { return kQueueKeyPrefix + item_id; }

std::map<std::string, std::string> run_of_references(const nlohmann::json& params) {
  std::map<std::string, std::string> out;
  if (!params.is_object()) return out;
  for (const auto& [name, value] : params.items()) {
    if (!value.is_object() || !value.contains(kRunOfKey)) continue;
    if (value.size() != 1 || !value[kRunOfKey].is_string() || value[kRunOfKey].get<std::string>().empty()) {
      throw Error(ErrorClass::bad_parameter,
                  "parameter '" + name + "' must be {\"$run_of\": \"<queue item id>\"} alone, not " + value.dump(),
                  "the item's run id is put in when it comes up");
    }
    out[name] = value[kRunOfKey].get<std::string>();
  }
  return out;
}

bool QueueItem::has_unresolved_references() const {
  for (const auto& [name, ref] : param_refs) {
    if (params.is_object() && params.contains(name) && params[name].is_object()) return true;
  }
  return false;
}

nlohmann::json QueueItem::to_json() const {
  auto opt = [](const std::optional<std::string>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); };
  return {{"id", id},
          {"position", position ? nlohmann::json(*position) : nlohmann::json(nullptr)},
          {"campaign", campaign},
          {"params", params},
          {"on_failure", to_string(on_failure)},
          {"state", to_string(state)},
          {"execution_id", opt(execution_id)},
          {"reason", reason},
          {"created_at", created_at},
          {"updated_at", updated_at},
          {"started_at", opt(started_at)},
          {"finished_at", opt(finished_at)},
          {"param_refs", param_refs},
          {"group_id", opt(group_id)},
          {"step", opt(step)}};
}

QueueItem QueueStore::read(Statement& st) {
  QueueItem q;
  q.id = st.text(0);
  if (!st.is_null(1)) q.position = st.int64(1);
  q.campaign = st.text(2);
  q.params = nlohmann::json::parse(st.text(3), nullptr, false);
  q.on_failure = st.text(4) == "continue" ? OnFailure::go_on : OnFailure::stop;
  // The CHECK constraint admits only known states.
  q.state = queue_item_state_from_string(st.text(5)).value_or(QueueItemState::failed);
  q.execution_id = optional_text(st, 6);
  q.reason = st.text(7);
  q.created_at = st.text(8);
  q.updated_at = st.text(9);
  q.started_at = optional_text(st, 10);
  q.finished_at = optional_text(st, 11);
  auto refs = nlohmann::json::parse(st.text(12), nullptr, false);
  if (refs.is_object()) {
    for (const auto& [name, ref] : refs.items()) {
      if (ref.is_string()) q.param_refs[name] = ref.get<std::string>();
    }
  }
  q.group_id = optional_text(st, 13);
  q.step = optional_text(st, 14);
  return q;
}

std::optional<QueueItem> QueueStore::item(const std::string& id) {
  auto st = store_.db_.prepare(std::string("SELECT ") + kItemColumns + " FROM queue_items WHERE id = ?1");
  st.bind(1, std::string_view(id));
  if (!st.step()) return std::nullopt;
  return read(st);
}

QueueItem QueueStore::require(const std::string& id) {
  auto q = item(id);
  if (!q) throw Error(ErrorClass::not_found, "no queue item with id '" + id + "'", "colorlab queue list shows the queue");
  return *q;
}

void QueueStore::event(const std::string& change, const QueueItem& item) {
  store_.append_event("queue", {{"change", change}, {"item", item.to_json()}});
}

// Queued items keep positions 1..N in their order, whatever left the queue in between.
// Read first, then write: an UPDATE whose subquery reads the rows it is changing would depend on
// the order SQLite visits them.
void QueueStore::renumber() {
  auto& db = store_.db_;
  std::vector<std::string> ids;
  {
    auto st = db.prepare("SELECT id FROM queue_items WHERE state = 'queued' ORDER BY position, id");
    while (st.step()) ids.push_back(st.text(0));
  }
  auto set = db.prepare("UPDATE queue_items SET position = ?2 WHERE id = ?1 AND position IS NOT ?2");
  for (std::size_t i = 0; i < ids.size(); ++i) {
    set.bind(1, std::string_view(ids[i])).bind(2, static_cast<std::int64_t>(i + 1));
    set.run();
    set.reset();
  }
}

QueueStore::Enqueued QueueStore::enqueue(const NewQueueItem& n) {
  Transaction tx(store_.db_);
  auto enqueued = insert(n);
  tx.commit();
  return enqueued;
}

namespace {

std::string describe_ref(const std::string& param, const QueueItem& target) {
  return "parameter '" + param + "' takes the run of queue item " + target.id + " (" + target.campaign + ")";
}

}  // namespace

QueueStore::Enqueued QueueStore::insert(const NewQueueItem& n) {
  auto& db = store_.db_;
  if (n.idempotency_key) {
    auto st = db.prepare("SELECT id FROM queue_items WHERE idempotency_key = ?1");
    st.bind(1, std::string_view(*n.idempotency_key));
    if (st.step()) return {require(st.text(0)), false};
  }
  // A referenced item is earlier in the queue by construction (this one goes last), unless it ended badly.
  for (const auto& [param, ref] : n.param_refs) {
    auto target = item(ref);
    if (!target) {
      throw QueueConflict("queue-reference-unknown",
                          "parameter '" + param + "' references queue item '" + ref + "', which does not exist",
                          "a reference names an item queued before this one: colorlab queue list shows them");
    }
    if (target->state == QueueItemState::failed || target->state == QueueItemState::skipped ||
        target->state == QueueItemState::removed) {
      throw QueueConflict("queue-reference-ended",
                          describe_ref(param, *target) + ", which " + std::string(to_string(target->state)) +
                              (target->reason.empty() ? "" : " (" + target->reason + ")"),
                          "it will never have a run: queue that campaign again and reference the new item");
    }
  }
  std::string id = n.id.value_or(new_uuid_v7());
  std::string now = now_iso8601();
  nlohmann::json refs(n.param_refs);
  db.prepare(
        "INSERT INTO queue_items (id, position, campaign, params, on_failure, state, idempotency_key, created_at, "
        "updated_at, param_refs, group_id, step) VALUES (?1, (SELECT COALESCE(MAX(position), 0) + 1 FROM queue_items "
        "WHERE state = 'queued'), ?2, ?3, ?4, 'queued', ?5, ?6, ?6, ?7, ?8, ?9)")
      .bind(1, std::string_view(id))
      .bind(2, std::string_view(n.campaign))
      .bind(3, std::string_view(n.params.dump()))
      .bind(4, to_string(n.on_failure))
      .bind(5, n.idempotency_key)
      .bind(6, std::string_view(now))
      .bind(7, std::string_view(refs.dump()))
      .bind(8, n.group_id)
      .bind(9, n.step)
      .run();
  auto created = require(id);
  event("enqueued", created);
  return {created, true};
}

QueueStore::EnqueuedGroup QueueStore::enqueue_group(const std::string& group_id, const std::string& sequence,
                                                    const nlohmann::json& options,
                                                    const std::vector<NewQueueItem>& items) {
  auto& db = store_.db_;
  if (!items.empty() && items.front().idempotency_key) {
    auto st = db.prepare("SELECT group_id FROM queue_items WHERE idempotency_key = ?1");
    st.bind(1, std::string_view(*items.front().idempotency_key));
    if (st.step() && !st.is_null(0)) {
      if (auto g = group(st.text(0))) return {*g, false};
    }
  }
  Transaction tx(db);
  db.prepare("INSERT INTO queue_groups (id, sequence, options, created_at) VALUES (?1, ?2, ?3, ?4)")
      .bind(1, std::string_view(group_id))
      .bind(2, std::string_view(sequence))
      .bind(3, std::string_view(options.dump()))
      .bind(4, std::string_view(now_iso8601()))
      .run();
  for (auto n : items) {
    n.group_id = group_id;
    insert(n);
  }
  store_.append_event("queue", {{"change", "group-enqueued"}, {"group_id", group_id}, {"sequence", sequence}});
  tx.commit();
  return {*group(group_id), true};
}

std::optional<QueueGroup> QueueStore::group(const std::string& id) {
  auto& db = store_.db_;
  QueueGroup g;
  {
    auto st = db.prepare("SELECT id, sequence, options, created_at FROM queue_groups WHERE id = ?1");
    st.bind(1, std::string_view(id));
    if (!st.step()) return std::nullopt;
    g.id = st.text(0);
    g.sequence = st.text(1);
    g.options = nlohmann::json::parse(st.text(2), nullptr, false);
    if (!g.options.is_object()) g.options = nlohmann::json::object();
    g.created_at = st.text(3);
  }
  auto st = db.prepare(std::string("SELECT ") + kItemColumns + " FROM queue_items WHERE group_id = ?1 ORDER BY rowid");
  st.bind(1, std::string_view(id));
  while (st.step()) g.items.push_back(read(st));
  return g;
}

QueueItem QueueStore::resolve(const std::string& id, const nlohmann::json& params) {
  auto& db = store_.db_;
  Transaction tx(db);
  db.prepare("UPDATE queue_items SET params = ?2, updated_at = ?3 WHERE id = ?1 AND state = 'queued'")
      .bind(1, std::string_view(id))
      .bind(2, std::string_view(params.dump()))
      .bind(3, std::string_view(now_iso8601()))
      .run();
  auto q = require(id);
  event("resolved", q);
  tx.commit();
  return q;
}

std::vector<QueueItem> QueueStore::pending() {
  auto st = store_.db_.prepare(std::string("SELECT ") + kItemColumns +
                               " FROM queue_items WHERE state IN ('running', 'queued') "
                               "ORDER BY state = 'queued', position, id");
  std::vector<QueueItem> out;
  while (st.step()) out.push_back(read(st));
  return out;
}

std::optional<QueueItem> QueueStore::next_queued() {
  auto st = store_.db_.prepare(std::string("SELECT ") + kItemColumns +
                               " FROM queue_items WHERE state = 'queued' ORDER BY position, id LIMIT 1");
  if (!st.step()) return std::nullopt;
  return read(st);
}

std::vector<QueueItem> QueueStore::history(unsigned limit) {
  auto st = store_.db_.prepare(std::string("SELECT ") + kItemColumns +
                               " FROM queue_items WHERE state NOT IN ('running', 'queued') "
                               "ORDER BY updated_at DESC, id DESC LIMIT ?1");
  st.bind(1, static_cast<std::int64_t>(limit));
  std::vector<QueueItem> out;
  while (st.step()) out.push_back(read(st));
  return out;
}

namespace {

void require_queued(const QueueItem& q, const std::string& action) {
  if (q.state == QueueItemState::queued) return;
  std::string hint = q.state == QueueItemState::running && q.execution_id
                         ? "it is running as execution " + *q.execution_id + ": colorlab abort " + *q.execution_id +
                               " stops it"
                         : "only items still waiting in the queue can be " + action;
  throw Error(ErrorClass::conflict, "queue item " + q.id + " is " + std::string(to_string(q.state)) + ", not queued",
              hint);
}

}  // namespace

QueueItem QueueStore::remove(const std::string& id) {
  auto& db = store_.db_;
  Transaction tx(db);
  auto q = require(id);
  require_queued(q, "removed");
  db.prepare(
        "UPDATE queue_items SET state = 'removed', position = NULL, reason = 'removed by a client', updated_at = ?2, "
        "finished_at = ?2 WHERE id = ?1")
      .bind(1, std::string_view(id))
      .bind(2, std::string_view(now_iso8601()))
      .run();
  renumber();
  q = require(id);
  event("removed", q);
  tx.commit();
  return q;
}

// The queued items in order with `moved` at `position`: every item's queued references must still
// come before it.
void QueueStore::check_order_after_move(const QueueItem& moved, std::int64_t position) {
  std::vector<QueueItem> order;
  for (auto& q : pending()) {
    if (q.state == QueueItemState::queued && q.id != moved.id) order.push_back(q);
  }
  order.insert(order.begin() + (position - 1), moved);
  std::map<std::string, std::size_t> at;
  for (std::size_t i = 0; i < order.size(); ++i) at[order[i].id] = i;
  for (std::size_t i = 0; i < order.size(); ++i) {
    for (const auto& [param, ref] : order[i].param_refs) {
      auto it = at.find(ref);
      if (it == at.end() || it->second < i) continue;
      const auto& target = order[it->second];
      throw QueueConflict("queue-reference-order",
                          "moving item " + moved.id + " to position " + std::to_string(position) + " would run item " +
                              order[i].id + " (" + order[i].campaign + ") before item " + target.id + " (" +
                              target.campaign + ") whose run its parameter '" + param + "' takes",
                          "an item that takes another's run must stay after it; move them together");
    }
  }
}

QueueItem QueueStore::move(const std::string& id, std::int64_t position) {
  auto& db = store_.db_;
  Transaction tx(db);
  auto q = require(id);
  require_queued(q, "moved");
  std::int64_t count = 0;
  {
    auto st = db.prepare("SELECT COUNT(*) FROM queue_items WHERE state = 'queued'");
    if (st.step()) count = st.int64(0);
  }
  if (position < 1 || position > count) {
    throw Error(ErrorClass::bad_parameter,
                "position " + std::to_string(position) + " is outside 1.." + std::to_string(count) + " (the queued items)",
                "1 runs next; " + std::to_string(count) + " runs last");
  }
  std::int64_t from = *q.position;
  check_order_after_move(q, position);
  // Shift the items between the old and the new place by one, then put this one there.
  if (position < from) {
    db.prepare("UPDATE queue_items SET position = position + 1 WHERE state = 'queued' AND position >= ?1 AND position < ?2")
        .bind(1, position)
        .bind(2, from)
        .run();
  } else if (position > from) {
    db.prepare("UPDATE queue_items SET position = position - 1 WHERE state = 'queued' AND position > ?2 AND position <= ?1")
        .bind(1, position)
        .bind(2, from)
        .run();
  }
  db.prepare("UPDATE queue_items SET position = ?2, updated_at = ?3 WHERE id = ?1")
      .bind(1, std::string_view(id))
      .bind(2, position)
      .bind(3, std::string_view(now_iso8601()))
      .run();
  q = require(id);
  event("moved", q);
  tx.commit();
  return q;
}

QueueItem QueueStore::mark_running(const std::string& id, const std::string& execution_id) {
  auto& db = store_.db_;
  Transaction tx(db);
  std::string now = now_iso8601();
  db.prepare(
        "UPDATE queue_items SET state = 'running', position = NULL, execution_id = ?2, updated_at = ?3, "
        "started_at = ?3 WHERE id = ?1")
      .bind(1, std::string_view(id))
      .bind(2, std::string_view(execution_id))
      .bind(3, std::string_view(now))
      .run();
  renumber();
  auto q = require(id);
  event("started", q);
  tx.commit();
  return q;
}

QueueItem QueueStore::finish(const std::string& id, QueueItemState state, const std::string& reason) {
  if (state != QueueItemState::done && state != QueueItemState::failed && state != QueueItemState::skipped) {
    throw Error(ErrorClass::internal, "a queue item ends done, failed or skipped, not " + std::string(to_string(state)));
  }
  auto& db = store_.db_;
  Transaction tx(db);
  std::string now = now_iso8601();
  db.prepare(
        "UPDATE queue_items SET state = ?2, position = NULL, reason = ?3, updated_at = ?4, finished_at = ?4 "
        "WHERE id = ?1")
      .bind(1, std::string_view(id))
      .bind(2, to_string(state))
      .bind(3, std::string_view(reason))
      .bind(4, std::string_view(now))
      .run();
  renumber();
  auto q = require(id);
  event(std::string(to_string(state)), q);
  tx.commit();
  return q;
}

int QueueStore::adopt_started_executions() {
  auto& db = store_.db_;
  // Looked for on every poll of an idle queue: read only, a write transaction only when there is one.
  std::vector<std::pair<std::string, std::string>> found;
  {
    auto st = db.prepare(
        "SELECT q.id, e.id FROM queue_items AS q JOIN executions AS e ON e.idempotency_key = ?1 || q.id "
        "WHERE q.state = 'queued'");
    st.bind(1, std::string_view(kQueueKeyPrefix));
    while (st.step()) found.emplace_back(st.text(0), st.text(1));
  }
  if (found.empty()) return 0;
  Transaction tx(db);
  std::string now = now_iso8601();
  for (const auto& [item_id, execution_id] : found) {
    db.prepare(
          "UPDATE queue_items SET state = 'running', position = NULL, execution_id = ?2, updated_at = ?3, "
          "started_at = ?3 WHERE id = ?1")
        .bind(1, std::string_view(item_id))
        .bind(2, std::string_view(execution_id))
        .bind(3, std::string_view(now))
        .run();
    event("started", require(item_id));
  }
  renumber();
  tx.commit();
  return static_cast<int>(found.size());
}

QueueStatus QueueStore::status() {
  auto st = store_.db_.prepare("SELECT started, halted, reason, updated_at FROM queue_state WHERE id = 1");
  QueueStatus s;
  if (st.step()) {
    s.started = st.int64(0) != 0;
    s.halted = st.int64(1) != 0;
    s.reason = st.text(2);
    s.updated_at = st.text(3);
  }
  return s;
}

void QueueStore::set_status(bool started, bool halted, const std::string& reason) {
  auto& db = store_.db_;
  Transaction tx(db);
  db.prepare("UPDATE queue_state SET started = ?1, halted = ?2, reason = ?3, updated_at = ?4 WHERE id = 1")
      .bind(1, static_cast<std::int64_t>(started))
      .bind(2, static_cast<std::int64_t>(halted))
      .bind(3, std::string_view(reason))
      .bind(4, std::string_view(now_iso8601()))
      .run();
  store_.append_event("queue", {{"queue", started ? "started" : "stopped"}, {"halted", halted}, {"reason", reason}});
  tx.commit();
}

}  // namespace colorlab::store
