// The night's queue as stored: the 2 → 3 migration keeps what was there and adds the queue;
// queued items keep positions 1..N through move, remove and start; only queued items can be
// removed or moved (typed errors); a retried enqueue returns the same item; the queue's rows and
// state survive a reopen; an execution started under an item's key is adopted, never duplicated;
// every change is in the event log. References to an earlier item's run (issue 11): the 5 → 6
// migration keeps queued items; an unknown or ended reference is refused at enqueue, a move that puts
// an item before its reference is refused, each with its typed code; resolve writes the run in; a
// sequence's items go in as one group.
#include <functional>

#include <gtest/gtest.h>
#include <sqlite3.h>

#include "colorlab/core/error.hpp"
#include "colorlab/core/ids.hpp"
#include "colorlab/store/queue.hpp"
#include "colorlab/store/schema.hpp"
#include "colorlab/store/store.hpp"
#include "colorlab/testing/temp_dir.hpp"

using colorlab::Error;
using colorlab::ErrorClass;
using colorlab::store::NewQueueItem;
using colorlab::store::OnFailure;
using colorlab::store::QueueItemState;
using colorlab::store::QueueStore;
using colorlab::store::Store;
using colorlab::testing::TempDir;
using nlohmann::json;

namespace {

NewQueueItem spot(int readings, OnFailure on_failure = OnFailure::stop) {
  return NewQueueItem{"luminance-spot", {{"readings", readings}, {"interval_s", 0}}, on_failure, std::nullopt};
}

void exec_sql(const std::filesystem::path& db, const std::string& sql) {
  sqlite3* h = nullptr;
  ASSERT_EQ(sqlite3_open(db.c_str(), &h), SQLITE_OK);
  char* error = nullptr;
  int rc = sqlite3_exec(h, sql.c_str(), nullptr, nullptr, &error);
  std::string message = error ? error : "";
  sqlite3_free(error);
  sqlite3_close(h);
  ASSERT_EQ(rc, SQLITE_OK) << message;
}

std::vector<std::string> queued_ids(QueueStore& q) {
  std::vector<std::string> out;
  std::int64_t expected = 1;
  for (const auto& item : q.pending()) {
    if (item.state != QueueItemState::queued) continue;
    EXPECT_EQ(item.position, expected++) << "positions must be 1..N without gaps";
    out.push_back(item.id);
  }
  return out;
}

// A real execution for the item to become (queue_items.execution_id references executions).
std::string new_execution(Store& store, std::optional<std::string> key = std::nullopt) {
  colorlab::store::NewRun run;
  run.campaign = "luminance-spot";
  run.params = {{"readings", 1}};
  run.instruments = json::array();
  run.idempotency_key = std::move(key);
  return store.create_execution(run).execution.id;
}

Error error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e;
  }
  ADD_FAILURE() << "no error thrown";
  return Error(ErrorClass::internal, "none");
}

}  // namespace

TEST(queue_store, MigrationFromVersionTwoKeepsTheDataAndAddsAStoppedEmptyQueue) {
  TempDir dir;
  auto path = dir / "colorlab.db";
  std::string execution_id;
  {
    Store store(path);
    colorlab::store::NewRun run;
    run.campaign = "luminance-spot";
    run.params = {{"readings", 1}};
    run.instruments = json::array();
    run.script_sha256 = std::string(64, 'a');
    run.script_source = "return {}";
    execution_id = store.create_execution(run).execution.id;
  }
  // The file as version 2 left it: no queue tables (nor the later call timings, nor executions' suspension).
  exec_sql(path, "DROP INDEX runs_by_campaign; DROP INDEX runs_by_status; ALTER TABLE runs DROP COLUMN list_summary; DROP TABLE queue_groups; DROP TABLE queue_items; DROP TABLE queue_state; DROP TABLE call_timings; DROP TABLE run_blobs; DROP TABLE blobs; DROP TABLE api_keys; ALTER TABLE executions DROP COLUMN suspension; PRAGMA user_version = 2;");
  Store store(path);
  {
    colorlab::store::Database db(path.string(), true);
    EXPECT_EQ(colorlab::store::schema_version(db), colorlab::store::kSchemaVersion);
  }
  EXPECT_TRUE(store.execution(execution_id)) << "the migration must keep what was stored";
  QueueStore queue(store);
  EXPECT_TRUE(queue.pending().empty());
  auto status = queue.status();
  EXPECT_FALSE(status.started);
  EXPECT_FALSE(status.halted);
  EXPECT_FALSE(status.updated_at.empty());
}

TEST(queue_store, QueuedItemsKeepPositionsOneToNThroughMoveRemoveAndStart) {
  TempDir dir;
  Store store(dir / "colorlab.db");
  QueueStore queue(store);
  std::vector<std::string> ids;
  for (int i = 1; i <= 4; ++i) {
    auto e = queue.enqueue(spot(i));
    ASSERT_TRUE(e.created);
    EXPECT_EQ(e.item.position, i);
    EXPECT_EQ(e.item.state, QueueItemState::queued);
    EXPECT_EQ(e.item.params["readings"], i);
    EXPECT_EQ(e.item.id.size(), 36u);
    EXPECT_EQ(e.item.id[14], '7') << "ids are UUIDv7: " << e.item.id;
    ids.push_back(e.item.id);
  }
  EXPECT_EQ(queued_ids(queue), ids);

  auto moved = queue.move(ids[3], 1);
  EXPECT_EQ(moved.position, 1);
  EXPECT_EQ(queued_ids(queue), (std::vector<std::string>{ids[3], ids[0], ids[1], ids[2]}));
  queue.move(ids[3], 4);
  EXPECT_EQ(queued_ids(queue), ids);
  queue.move(ids[0], 3);
  EXPECT_EQ(queued_ids(queue), (std::vector<std::string>{ids[1], ids[2], ids[0], ids[3]}));

  auto removed = queue.remove(ids[2]);
  EXPECT_EQ(removed.state, QueueItemState::removed);
  EXPECT_FALSE(removed.position);
  EXPECT_EQ(removed.reason, "removed by a client");
  EXPECT_EQ(queued_ids(queue), (std::vector<std::string>{ids[1], ids[0], ids[3]}));

  ASSERT_EQ(queue.next_queued()->id, ids[1]);
  auto execution = new_execution(store);
  auto running = queue.mark_running(ids[1], execution);
  EXPECT_EQ(running.state, QueueItemState::running);
  EXPECT_EQ(running.execution_id, execution);
  EXPECT_TRUE(running.started_at);
  EXPECT_EQ(queued_ids(queue), (std::vector<std::string>{ids[0], ids[3]}));
  EXPECT_EQ(queue.pending().front().id, ids[1]) << "the running item comes first";

  auto done = queue.finish(ids[1], QueueItemState::done, "");
  EXPECT_EQ(done.state, QueueItemState::done);
  EXPECT_TRUE(done.finished_at);
  auto history = queue.history(10);
  ASSERT_EQ(history.size(), 2u);
  EXPECT_EQ(history[0].id, ids[1]) << "most recently ended first";
  EXPECT_EQ(history[1].id, ids[2]);
  EXPECT_EQ(queue.history(1).size(), 1u);
}

TEST(queue_store, OnlyQueuedItemsCanBeRemovedOrMovedWithTypedErrors) {
  TempDir dir;
  Store store(dir / "colorlab.db");
  QueueStore queue(store);
  auto a = queue.enqueue(spot(1)).item;
  auto b = queue.enqueue(spot(2)).item;
  EXPECT_EQ(error_of([&] { queue.remove("no-such-item"); }).cls(), ErrorClass::not_found);
  EXPECT_EQ(error_of([&] { queue.move("no-such-item", 1); }).cls(), ErrorClass::not_found);
  auto out_of_range = error_of([&] { queue.move(b.id, 3); });
  EXPECT_EQ(out_of_range.cls(), ErrorClass::bad_parameter);
  EXPECT_NE(std::string(out_of_range.what()).find("1..2"), std::string::npos) << out_of_range.what();
  EXPECT_EQ(error_of([&] { queue.move(b.id, 0); }).cls(), ErrorClass::bad_parameter);
  auto execution = new_execution(store);
  queue.mark_running(a.id, execution);
  auto running = error_of([&] { queue.remove(a.id); });
  EXPECT_EQ(running.cls(), ErrorClass::conflict);
  EXPECT_NE(running.hint().find("colorlab abort " + execution), std::string::npos) << running.hint();
  EXPECT_EQ(error_of([&] { queue.move(a.id, 1); }).cls(), ErrorClass::conflict);
  queue.remove(b.id);
  EXPECT_EQ(error_of([&] { queue.remove(b.id); }).cls(), ErrorClass::conflict);
  EXPECT_EQ(error_of([&] { queue.finish(a.id, QueueItemState::queued, ""); }).cls(), ErrorClass::internal);
  EXPECT_EQ(error_of([] { colorlab::store::on_failure_from_string("retry"); }).cls(), ErrorClass::bad_parameter);
  EXPECT_EQ(colorlab::store::on_failure_from_string("continue"), OnFailure::go_on);
}

TEST(queue_store, TheSchemaRefusesStatesAndPoliciesItDoesNotKnow) {
  TempDir dir;
  auto path = dir / "colorlab.db";
  { Store store(path); }
  sqlite3* h = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &h), SQLITE_OK);
  auto insert = [&](const char* on_failure, const char* state) {
    std::string sql = std::string("INSERT INTO queue_items (id, campaign, params, on_failure, state, created_at, updated_at) "
                                  "VALUES (hex(randomblob(16)), 'x', '{}', '") +
                      on_failure + "', '" + state + "', 'now', 'now')";
    return sqlite3_exec(h, sql.c_str(), nullptr, nullptr, nullptr);
  };
  EXPECT_EQ(insert("stop", "queued"), SQLITE_OK);
  EXPECT_NE(insert("retry", "queued"), SQLITE_OK);
  EXPECT_NE(insert("stop", "paused"), SQLITE_OK);
  EXPECT_NE(sqlite3_exec(h, "INSERT INTO queue_state (id, started, halted, reason, updated_at) VALUES (2, 0, 0, '', 'now')",
                         nullptr, nullptr, nullptr),
            SQLITE_OK)
      << "the queue's state is one row";
  sqlite3_close(h);
}

TEST(queue_store, ARetriedEnqueueWithTheSameKeyReturnsTheSameItem) {
  TempDir dir;
  Store store(dir / "colorlab.db");
  QueueStore queue(store);
  auto item = spot(3);
  item.idempotency_key = "night-7";
  auto first = queue.enqueue(item);
  auto again = queue.enqueue(item);
  EXPECT_TRUE(first.created);
  EXPECT_FALSE(again.created);
  EXPECT_EQ(again.item.id, first.item.id);
  EXPECT_EQ(queue.pending().size(), 1u);
  item.idempotency_key = "night-8";
  EXPECT_TRUE(queue.enqueue(item).created);
}

TEST(queue_store, ItemsAndTheQueuesStateSurviveAReopen) {
  TempDir dir;
  std::string a, b;
  {
    Store store(dir / "colorlab.db");
    QueueStore queue(store);
    a = queue.enqueue(spot(1, OnFailure::go_on)).item.id;
    b = queue.enqueue(spot(2)).item.id;
    queue.set_status(false, true, "item x failed");
  }
  Store store(dir / "colorlab.db");
  QueueStore queue(store);
  auto pending = queue.pending();
  ASSERT_EQ(pending.size(), 2u);
  EXPECT_EQ(pending[0].id, a);
  EXPECT_EQ(pending[0].on_failure, OnFailure::go_on);
  EXPECT_EQ(pending[1].id, b);
  EXPECT_EQ(pending[1].params["readings"], 2);
  auto status = queue.status();
  EXPECT_FALSE(status.started);
  EXPECT_TRUE(status.halted);
  EXPECT_EQ(status.reason, "item x failed");
  queue.set_status(true, false, "started by a client");
  EXPECT_TRUE(queue.status().started);
  EXPECT_FALSE(queue.status().halted);
}

// A daemon killed after starting an item's execution but before recording it: the execution
// carries the item's key, and the item becomes that execution's instead of starting another.
TEST(queue_store, AnExecutionStartedUnderTheItemsKeyIsAdoptedNotDuplicated) {
  TempDir dir;
  Store store(dir / "colorlab.db");
  QueueStore queue(store);
  auto a = queue.enqueue(spot(1)).item;
  auto b = queue.enqueue(spot(2)).item;
  EXPECT_EQ(queue.adopt_started_executions(), 0);
  new_execution(store, "another key");
  EXPECT_EQ(queue.adopt_started_executions(), 0);
  auto execution = new_execution(store, colorlab::store::queue_execution_key(a.id));
  EXPECT_EQ(queue.adopt_started_executions(), 1);
  auto adopted = *queue.item(a.id);
  EXPECT_EQ(adopted.state, QueueItemState::running);
  EXPECT_EQ(adopted.execution_id, execution);
  EXPECT_EQ(queue.next_queued()->id, b.id);
  EXPECT_EQ(queue.next_queued()->position, 1);
  EXPECT_EQ(queue.adopt_started_executions(), 0) << "adopted once";
}

TEST(queue_store, EveryChangeIsInTheEventLog) {
  TempDir dir;
  Store store(dir / "colorlab.db");
  QueueStore queue(store);
  auto a = queue.enqueue(spot(1)).item;
  auto b = queue.enqueue(spot(2)).item;
  queue.move(b.id, 1);
  queue.remove(b.id);
  queue.set_status(true, false, "started by a client");
  auto execution = new_execution(store);
  queue.mark_running(a.id, execution);
  queue.finish(a.id, QueueItemState::failed, "finished_error: the tile is dirty");
  std::vector<std::string> changes;
  for (const auto& e : store.events(0, 100, "queue")) {
    changes.push_back(e.payload.contains("change") ? e.payload["change"].get<std::string>()
                                                   : "queue " + e.payload["queue"].get<std::string>());
    if (e.payload.contains("item")) {
      EXPECT_TRUE(e.payload["item"].contains("state")) << e.payload.dump();
    }
  }
  EXPECT_EQ(changes, (std::vector<std::string>{"enqueued", "enqueued", "moved", "removed", "queue started", "started",
                                               "failed"}));
  auto last = store.events(0, 100, "queue").back().payload["item"];
  EXPECT_EQ(last["reason"], "finished_error: the tile is dirty");
  EXPECT_EQ(last["execution_id"], execution);
}

namespace {

std::string conflict_code(const std::function<void()>& f) {
  try {
    f();
  } catch (const colorlab::store::QueueConflict& e) {
    EXPECT_EQ(e.cls(), ErrorClass::conflict);
    return e.code();
  } catch (const Error& e) {
    ADD_FAILURE() << "not a QueueConflict: " << e.what();
    return "";
  }
  ADD_FAILURE() << "no error thrown";
  return "";
}

NewQueueItem taking_run_of(const std::string& item_id) {
  NewQueueItem n{"characterize-camera", {{"reference_run", {{"$run_of", item_id}}}}, OnFailure::stop, std::nullopt};
  n.param_refs = colorlab::store::run_of_references(n.params);
  return n;
}

}  // namespace

TEST(queue_store, MigrationFromVersionFiveKeepsQueuedItemsWithoutReferences) {
  TempDir dir;
  auto path = dir / "colorlab.db";
  std::string id;
  {
    Store store(path);
    QueueStore queue(store);
    id = queue.enqueue(spot(3)).item.id;
  }
  exec_sql(path,
           "DROP INDEX queue_items_by_group; DROP TABLE queue_groups; ALTER TABLE queue_items DROP COLUMN param_refs; "
           "ALTER TABLE queue_items DROP COLUMN group_id; ALTER TABLE queue_items DROP COLUMN step; "
           "DROP INDEX runs_by_campaign; DROP INDEX runs_by_status; ALTER TABLE runs DROP COLUMN list_summary; ALTER TABLE executions DROP COLUMN suspension; PRAGMA user_version = 5;");
  Store store(path);
  {
    colorlab::store::Database db(path.string(), true);
    EXPECT_EQ(colorlab::store::schema_version(db), colorlab::store::kSchemaVersion);
  }
  QueueStore queue(store);
  auto item = queue.item(id);
  ASSERT_TRUE(item);
  EXPECT_EQ(item->params["readings"], 3);
  EXPECT_EQ(item->position, 1);
  EXPECT_TRUE(item->param_refs.empty());
  EXPECT_FALSE(item->group_id);
  EXPECT_FALSE(item->has_unresolved_references());
}

TEST(queue_store, RunOfReferencesAreReadAndMalformedOnesRefused) {
  using colorlab::store::run_of_references;
  auto refs = run_of_references({{"a", {{"$run_of", "x"}}}, {"b", "plain"}, {"c", {{"other", 1}}}});
  EXPECT_EQ(refs, (std::map<std::string, std::string>{{"a", "x"}}));
  EXPECT_EQ(error_of([] { run_of_references({{"a", {{"$run_of", 3}}}}); }).cls(), ErrorClass::bad_parameter);
  EXPECT_EQ(error_of([] { run_of_references({{"a", {{"$run_of", "x"}, {"more", 1}}}}); }).cls(),
            ErrorClass::bad_parameter);
  EXPECT_EQ(error_of([] { run_of_references({{"a", {{"$run_of", ""}}}}); }).cls(), ErrorClass::bad_parameter);
}

TEST(queue_store, AReferenceMustNameAnItemThatExistsAndCanStillRun) {
  TempDir dir;
  Store store(dir / "colorlab.db");
  QueueStore queue(store);
  EXPECT_EQ(conflict_code([&] { queue.enqueue(taking_run_of("0190a000-0000-7000-8000-000000000000")); }),
            "queue-reference-unknown");
  auto first = queue.enqueue(spot(1)).item;
  auto taker = queue.enqueue(taking_run_of(first.id));
  ASSERT_TRUE(taker.created);
  EXPECT_EQ(taker.item.param_refs, (std::map<std::string, std::string>{{"reference_run", first.id}}));
  EXPECT_TRUE(taker.item.has_unresolved_references());
  EXPECT_EQ(taker.item.to_json()["param_refs"]["reference_run"], first.id);

  auto gone = queue.enqueue(spot(2)).item;
  queue.remove(gone.id);
  EXPECT_EQ(conflict_code([&] { queue.enqueue(taking_run_of(gone.id)); }), "queue-reference-ended");
  auto failing = queue.enqueue(spot(2)).item;
  queue.mark_running(failing.id, new_execution(store));
  queue.finish(failing.id, QueueItemState::failed, "the tile is dirty");
  EXPECT_EQ(conflict_code([&] { queue.enqueue(taking_run_of(failing.id)); }), "queue-reference-ended");
  EXPECT_EQ(queued_ids(queue), (std::vector<std::string>{first.id, taker.item.id})) << "a refusal stores nothing";

  // Running and done items can be referenced: their run exists or will.
  auto running = queue.enqueue(spot(2)).item;
  queue.mark_running(running.id, new_execution(store));
  EXPECT_TRUE(queue.enqueue(taking_run_of(running.id)).created);
  queue.finish(running.id, QueueItemState::done, "");
  EXPECT_TRUE(queue.enqueue(taking_run_of(running.id)).created);
}

TEST(queue_store, AMoveThatPutsAnItemBeforeItsReferenceIsRefused) {
  TempDir dir;
  Store store(dir / "colorlab.db");
  QueueStore queue(store);
  auto a = queue.enqueue(spot(1)).item.id;
  auto b = queue.enqueue(spot(2)).item.id;
  auto c = queue.enqueue(taking_run_of(a)).item.id;  // a, b, c: c takes a's run
  EXPECT_EQ(conflict_code([&] { queue.move(c, 1); }), "queue-reference-order");
  EXPECT_EQ(conflict_code([&] { queue.move(a, 3); }), "queue-reference-order");
  EXPECT_EQ(queued_ids(queue), (std::vector<std::string>{a, b, c})) << "a refused move changes nothing";
  queue.move(c, 2);  // still after a
  EXPECT_EQ(queued_ids(queue), (std::vector<std::string>{a, c, b}));
  queue.move(b, 1);
  EXPECT_EQ(queued_ids(queue), (std::vector<std::string>{b, a, c}));
  queue.move(a, 1);
  EXPECT_EQ(queued_ids(queue), (std::vector<std::string>{a, b, c}));
  // Once a has started, c may go anywhere among the queued.
  queue.mark_running(a, new_execution(store));
  queue.move(c, 1);
  EXPECT_EQ(queued_ids(queue), (std::vector<std::string>{c, b}));
}

TEST(queue_store, ResolveWritesTheRunIdIntoTheItemDurably) {
  TempDir dir;
  auto path = dir / "colorlab.db";
  std::string taker;
  {
    Store store(path);
    QueueStore queue(store);
    auto a = queue.enqueue(spot(1)).item.id;
    taker = queue.enqueue(taking_run_of(a)).item.id;
    auto item = *queue.item(taker);
    json params = item.params;
    params["reference_run"] = "the-run";
    auto resolved = queue.resolve(taker, params);
    EXPECT_EQ(resolved.params["reference_run"], "the-run");
    EXPECT_FALSE(resolved.has_unresolved_references());
    EXPECT_EQ(resolved.param_refs.at("reference_run"), a) << "the reference is kept beside the resolved value";
  }
  Store store(path);
  QueueStore queue(store);
  EXPECT_EQ(queue.item(taker)->params["reference_run"], "the-run");
  bool logged = false;
  for (const auto& e : store.events(0, 100, "queue")) {
    if (e.payload.value("change", "") == "resolved") logged = true;
  }
  EXPECT_TRUE(logged);
}

TEST(queue_store, AGroupGoesInAtOnceWithItsReferencesAndARetryReturnsIt) {
  TempDir dir;
  Store store(dir / "colorlab.db");
  QueueStore queue(store);
  auto other = queue.enqueue(spot(1)).item.id;
  std::string first_id = colorlab::new_uuid_v7();
  NewQueueItem first = spot(2);
  first.id = first_id;
  first.step = "chart-read";
  first.idempotency_key = "g/chart-read";
  NewQueueItem second = taking_run_of(first_id);
  second.step = "characterize-camera";
  second.idempotency_key = "g/characterize-camera";
  auto made = queue.enqueue_group("group-1", "dissertation", {{"small", true}}, {first, second});
  ASSERT_TRUE(made.created);
  ASSERT_EQ(made.group.items.size(), 2u);
  EXPECT_EQ(made.group.sequence, "dissertation");
  EXPECT_EQ(made.group.options["small"], true);
  EXPECT_EQ(made.group.items[0].id, first_id);
  EXPECT_EQ(made.group.items[0].step, "chart-read");
  EXPECT_EQ(made.group.items[1].group_id, "group-1");
  EXPECT_EQ(made.group.items[1].param_refs.at("reference_run"), first_id);
  EXPECT_EQ(queued_ids(queue), (std::vector<std::string>{other, first_id, made.group.items[1].id}));

  auto again = queue.enqueue_group("group-2", "dissertation", json::object(), {first, second});
  EXPECT_FALSE(again.created);
  EXPECT_EQ(again.group.id, "group-1");
  EXPECT_EQ(queued_ids(queue).size(), 3u);
  EXPECT_FALSE(queue.group("group-2"));

  // A group whose reference is refused stores nothing of itself.
  NewQueueItem bad = taking_run_of("0190a000-0000-7000-8000-000000000000");
  EXPECT_EQ(conflict_code([&] { queue.enqueue_group("group-3", "x", json::object(), {spot(1), bad}); }),
            "queue-reference-unknown");
  EXPECT_FALSE(queue.group("group-3"));
  EXPECT_EQ(queued_ids(queue).size(), 3u);
}
