// The store's promises: forward-only migrations, refusal of newer or foreign files, durable
// measurements, unfinished scripted runs kept for resume (legacy ones finalised) at open, whole steps, idempotent execution creation, keyset paging.
#include <algorithm>
#include <cmath>
#include <gtest/gtest.h>
#include <sqlite3.h>

#include "colorlab/core/error.hpp"
#include "colorlab/store/schema.hpp"
#include "colorlab/store/store.hpp"
#include "colorlab/testing/temp_dir.hpp"

using colorlab::Error;
using colorlab::ErrorClass;
using colorlab::protocol::ExecutionStatus;
using colorlab::store::NewRun;
using colorlab::store::StepRecord;
using nlohmann::json;
using colorlab::store::Store;
using colorlab::testing::TempDir;

namespace {

NewRun luminance_run() {
  NewRun r;
  r.campaign = "luminance-spot";
  r.params = {{"readings", 2}};
  r.simulated = true;
  r.instruments = nlohmann::json::array({{{"id", "ls110"}}});
  return r;
}

// An execution of a stored script, ready for steps.
colorlab::store::ExecutionRecord scripted_execution(Store& store) {
  auto run = luminance_run();
  run.script_sha256 = "s1";
  run.script_source = "x";
  return store.create_execution(run).execution;
}

void set_user_version(const std::filesystem::path& db, int v) {
  sqlite3* h = nullptr;
  ASSERT_EQ(sqlite3_open(db.c_str(), &h), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(h, ("PRAGMA user_version = " + std::to_string(v)).c_str(), nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(h);
}

}  // namespace

TEST(Store, CreatesSchemaAtCurrentVersion) {
  TempDir dir;
  Store store(dir / "state/colorlab.db");
  colorlab::store::Database db((dir / "state/colorlab.db").string(), true);
  EXPECT_EQ(colorlab::store::schema_version(db), colorlab::store::kSchemaVersion);
}

TEST(Store, RefusesDatabaseFromNewerColorlab) {
  TempDir dir;
  { Store store(dir / "colorlab.db"); }
  set_user_version(dir / "colorlab.db", colorlab::store::kSchemaVersion + 1);
  try {
    Store again(dir / "colorlab.db");
    FAIL() << "a newer database must be refused";
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::io_error);
    EXPECT_NE(std::string(e.what()).find("newer"), std::string::npos) << e.what();
  }
}

TEST(Store, RefusesForeignDatabase) {
  TempDir dir;
  sqlite3* h = nullptr;
  ASSERT_EQ(sqlite3_open((dir / "other.db").c_str(), &h), SQLITE_OK);
  sqlite3_exec(h, "PRAGMA application_id = 1234; CREATE TABLE t(x);", nullptr, nullptr, nullptr);
  sqlite3_close(h);
  EXPECT_THROW(Store(dir / "other.db"), Error);
}

TEST(Store, RejectsGarbageFileWithTypedError) {
  TempDir dir;
  {
    FILE* f = std::fopen((dir / "colorlab.db").c_str(), "w");
    std::fputs("this is not a database, just some text that is long enough to be read as a header page....", f);
    std::fclose(f);
  }
  try {
    Store s(dir / "colorlab.db");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::io_error) << e.what();
  }
}

TEST(Store, MeasurementsSurviveReopenAndUnfinishedRunsAwaitResume) {
  TempDir dir;
  std::string run_id, exec_id, legacy_run, legacy_exec;
  {
    Store store(dir / "colorlab.db");
    auto run = luminance_run();
    run.script_sha256 = "abc";
    run.script_source = "return {run = function() end}";
    run.random_seed = 42;
    auto created = store.create_execution(run);
    ASSERT_TRUE(created.created);
    run_id = created.execution.run_id;
    exec_id = created.execution.id;
    store.mark_run_started(run_id);
    store.update_execution(exec_id, ExecutionStatus::running, 0.5, "reading/1");
    store.add_measurement(run_id, "reading/0", "ls110", true, "luminance", 245.5, "cd/m2", {{"raw", "OK00,   245.50"}});
    // One made before scripts were stored cannot be replayed.
    auto legacy = store.create_execution(luminance_run());
    legacy_run = legacy.execution.run_id;
    legacy_exec = legacy.execution.id;
    store.update_execution(legacy_exec, ExecutionStatus::running, 0.1, "reading/0");
    // The process "dies" here: no finish_run.
  }
  Store reopened(dir / "colorlab.db");
  // The scripted execution is left for the daemon to resume, exactly as it was.
  auto unfinished = reopened.unfinished_executions();
  ASSERT_EQ(unfinished.size(), 1u);
  EXPECT_EQ(unfinished[0].id, exec_id);
  EXPECT_EQ(unfinished[0].status, ExecutionStatus::running);
  EXPECT_EQ(unfinished[0].step, "reading/1");
  EXPECT_EQ(unfinished[0].random_seed, 42u);
  EXPECT_EQ(*reopened.script_source("abc"), "return {run = function() end}");
  EXPECT_EQ(reopened.interrupted_at_open(), 1);
  EXPECT_EQ(reopened.run(legacy_run)->status, "interrupted");
  EXPECT_EQ(reopened.execution(legacy_exec)->status, ExecutionStatus::interrupted);
  auto ms = reopened.measurements(run_id);
  ASSERT_EQ(ms.size(), 1u);
  EXPECT_DOUBLE_EQ(*ms[0].value, 245.5);
  EXPECT_TRUE(ms[0].simulated);
  EXPECT_EQ(ms[0].data["raw"], "OK00,   245.50");
}

// A campaign step is one transaction: journal, measurements, progress and event together, or none.
TEST(Store, CommittedStepIsWholeAndAStepStoredTwiceLeavesNothingHalfDone) {
  TempDir dir;
  Store store(dir / "colorlab.db");
  auto e = scripted_execution(store);
  StepRecord step;
  step.journal.push_back({0, "meter.measure", json::array(), {{"luminance", 245.5}}});
  step.measurements.push_back({"reading/0", "ls110", true, "luminance", 245.5, "cd/m2", nullptr});
  step.progress = 0.5;
  step.step = "reading/0";
  store.commit_step(e, step);
  EXPECT_EQ(store.journal(e.id).size(), 1u);
  EXPECT_EQ(store.measurement_steps(e.run_id), std::set<std::string>{"reading/0"});
  EXPECT_EQ(store.execution(e.id)->steps_committed, 1);
  auto events_before = store.events(0, 1000, std::nullopt).size();

  // The same measurement again (and a new journal entry) must fail whole.
  StepRecord again = step;
  again.journal[0].seq = 1;
  EXPECT_THROW(store.commit_step(e, again), colorlab::Error);
  EXPECT_EQ(store.journal(e.id).size(), 1u);
  EXPECT_EQ(store.measurements(e.run_id).size(), 1u);
  EXPECT_EQ(store.events(0, 1000, std::nullopt).size(), events_before);

  // Resume attempts count up and a committed step resets them.
  EXPECT_EQ(store.begin_resume(e.id), 1);
  EXPECT_EQ(store.begin_resume(e.id), 2);
  StepRecord next;
  next.journal.push_back({1, "meter.measure", json::array(), {{"luminance", 246.0}}});
  next.step = "reading/1";
  store.commit_step(e, next);
  EXPECT_EQ(store.execution(e.id)->resume_attempts, 0);
  auto summary = store.measurement_summary(e.run_id);
  EXPECT_EQ(summary["luminance"]["count"], 1);
  EXPECT_DOUBLE_EQ(summary["luminance"]["mean"].get<double>(), 245.5);
}

TEST(Store, RepeatedStepIsAConflictNotADuplicate) {
  TempDir dir;
  Store store(dir / "colorlab.db");
  auto e = store.create_execution(luminance_run()).execution;
  store.add_measurement(e.run_id, "reading/0", "ls110", false, "luminance", 1.0, "cd/m2", nullptr);
  EXPECT_TRUE(store.has_measurement(e.run_id, "reading/0"));
  try {
    store.add_measurement(e.run_id, "reading/0", "ls110", false, "luminance", 2.0, "cd/m2", nullptr);
    FAIL();
  } catch (const Error& err) {
    EXPECT_EQ(err.cls(), ErrorClass::conflict);
  }
  ASSERT_EQ(store.measurements(e.run_id).size(), 1u);
  EXPECT_DOUBLE_EQ(*store.measurements(e.run_id)[0].value, 1.0);
}

TEST(Store, IdempotencyKeyReturnsTheSameExecution) {
  TempDir dir;
  Store store(dir / "colorlab.db");
  auto run = luminance_run();
  run.idempotency_key = "night-2026-11-22";
  auto first = store.create_execution(run);
  auto second = store.create_execution(run);
  EXPECT_TRUE(first.created);
  EXPECT_FALSE(second.created);
  EXPECT_EQ(first.execution.id, second.execution.id);
  EXPECT_EQ(store.runs(10, std::nullopt).runs.size(), 1u);
}

TEST(Store, CursorPagingVisitsEveryRunOnceNewestFirst) {
  TempDir dir;
  Store store(dir / "colorlab.db");
  std::vector<std::string> created;
  for (int i = 0; i < 7; ++i) created.push_back(store.create_execution(luminance_run()).execution.run_id);
  std::vector<std::string> seen;
  std::optional<std::string> cursor;
  int pages = 0;
  do {
    auto page = store.runs(3, cursor);
    for (const auto& r : page.runs) seen.push_back(r.id);
    cursor = page.next_cursor;
    ++pages;
  } while (cursor);
  EXPECT_EQ(pages, 3);
  std::reverse(created.begin(), created.end());
  EXPECT_EQ(seen, created);
}

TEST(Store, RunsFilteredByCampaignAndStatusPageOnlyTheMatching) {
  TempDir dir;
  Store store(dir / "colorlab.db");
  std::vector<std::string> spots_finished;
  for (int i = 0; i < 9; ++i) {
    auto run = luminance_run();
    if (i % 3 == 0) run.campaign = "frame-average";
    auto id = store.create_execution(run).execution.run_id;
    if (i % 3 != 0 && i % 2 == 0) {
      store.finish_run(id, colorlab::protocol::ExecutionStatus::finished_ok, nlohmann::json::object(), nullptr);
      spots_finished.push_back(id);
    }
  }
  auto collect = [&](const colorlab::store::RunFilter& f) {
    std::vector<std::string> ids;
    std::optional<std::string> cursor;
    do {
      auto page = store.runs(2, cursor, f);
      EXPECT_LE(page.runs.size(), 2u);
      for (const auto& r : page.runs) {
        if (!f.campaign.empty()) {
          EXPECT_EQ(r.campaign, f.campaign);
        }
        if (!f.status.empty()) {
          EXPECT_EQ(r.status, f.status);
        }
        ids.push_back(r.id);
      }
      cursor = page.next_cursor;
    } while (cursor);
    return ids;
  };
  EXPECT_EQ(collect({"frame-average", ""}).size(), 3u);
  EXPECT_EQ(collect({"luminance-spot", ""}).size(), 6u);
  auto finished = collect({"luminance-spot", "finished_ok"});
  std::reverse(spots_finished.begin(), spots_finished.end());
  EXPECT_EQ(finished, spots_finished);
  EXPECT_TRUE(collect({"no-such-campaign", ""}).empty());
  EXPECT_EQ(collect({}).size(), 9u);
}

TEST(Store, ForeignCursorIsABadParameter) {
  TempDir dir;
  Store store(dir / "colorlab.db");
  for (const char* bad : {"abc", "-3", "12x", ""}) {
    try {
      store.runs(3, std::string(bad));
      FAIL() << bad;
    } catch (const Error& e) {
      EXPECT_EQ(e.cls(), ErrorClass::bad_parameter) << bad;
    }
  }
}

TEST(Store, ExecutionLifecycleKeepsRunExecutionAndEventLogInStep) {
  TempDir dir;
  Store store(dir / "colorlab.db");
  auto e = store.create_execution(luminance_run()).execution;
  store.start_execution(e);
  EXPECT_EQ(store.run(e.run_id)->status, "running");
  store.report_progress(e.id, 0.5, "reading/1");
  EXPECT_DOUBLE_EQ(store.execution(e.id)->progress, 0.5);
  EXPECT_EQ(store.execution(e.id)->step, "reading/1");
  store.finish_execution(e, ExecutionStatus::finished_error, "reading/1", nullptr, {{"code", "misread"}});
  auto run = store.run(e.run_id);
  auto exec = store.execution(e.id);
  EXPECT_EQ(run->status, "finished_error");
  EXPECT_EQ(run->error["code"], "misread");
  EXPECT_EQ(exec->status, ExecutionStatus::finished_error);
  EXPECT_EQ(exec->error["code"], "misread");
  auto events = store.events(0, 10, std::nullopt);
  ASSERT_EQ(events.size(), 3u);  // created, progress, finished
  EXPECT_EQ(events[0].topic, "execution");
  EXPECT_EQ(events[1].topic, "progress");
  EXPECT_EQ(events[1].payload["step"], "reading/1");
  EXPECT_EQ(events[2].payload["status"], "finished_error");
}

// Call timings are learned with their step and read back per key at the time
// scale nearest the lab's: the simulated lab's seconds shrink, the daemon's own time does not.
TEST(Store, CallTimingsAccumulateWithTheirStepAndAreReadAtTheNearestTimeScale) {
  TempDir dir;
  Store store(dir / "colorlab.db");
  auto e = scripted_execution(store);
  StepRecord step;
  step.journal.push_back({0, "meter.measure", json::array(), {{"luminance", 1.0}}});
  step.timings = {{"meter.measure", 1.0}, {"meter.measure", 3.0}, {"wait_stable cold D65", 400.0}};
  step.time_scale = 100;
  store.commit_step(e, step);
  StepRecord fast;
  fast.journal.push_back({1, "meter.measure", json::array(), {{"luminance", 1.0}}});
  fast.timings = {{"meter.measure", 20.0}};
  fast.time_scale = 1000;
  store.commit_step(e, fast);
  auto at_200 = store.call_timings(200);  // ×200 is nearer ×100 than ×1000 (by ratio)
  ASSERT_EQ(at_200.count("meter.measure"), 1u);
  EXPECT_EQ(at_200["meter.measure"].n, 2);
  EXPECT_DOUBLE_EQ(at_200["meter.measure"].mean_s, 2.0);
  EXPECT_NEAR(at_200["meter.measure"].stdev_s, std::sqrt(2.0), 1e-9);
  EXPECT_DOUBLE_EQ(at_200["wait_stable cold D65"].mean_s, 400.0);
  auto at_800 = store.call_timings(800);
  EXPECT_DOUBLE_EQ(at_800["meter.measure"].mean_s, 20.0);
  EXPECT_DOUBLE_EQ(at_800["wait_stable cold D65"].mean_s, 400.0);  // only ever timed at ×100
}

// Schema 7: a suspended execution keeps why it waits (the crash-loop guard's back-off among it); running
// again or ended, it waits for nothing. A version-6 file gains the column with its executions intact.
TEST(Store, ASuspensionIsStoredWhileSuspendedAndClearedAfter) {
  TempDir dir;
  auto path = dir / "colorlab.db";
  std::string id;
  {
    Store store(path);
    auto e = scripted_execution(store);
    id = e.id;
    nlohmann::json why{{"category", "crash-loop"}, {"retry", 1}, {"retry_at", "2026-11-28T02:15:07.311Z"}};
    store.set_execution_status(e, ExecutionStatus::suspended, "crash loop: …", nullptr, why);
    EXPECT_EQ(store.execution(id)->suspension, why);
    EXPECT_EQ(store.execution(id)->to_json()["suspension"], why);
    auto events = store.events(0, 100, std::string("execution"));
    EXPECT_EQ(events.back().payload["suspension"], why);
    store.set_execution_status(e, ExecutionStatus::running, "resumed");
    EXPECT_TRUE(store.execution(id)->suspension.is_null());
    EXPECT_FALSE(store.execution(id)->to_json().contains("suspension"));
    store.set_execution_status(e, ExecutionStatus::suspended, "again", nullptr, why);
    store.finish_execution(e, ExecutionStatus::finished_error, "s", nullptr, {{"code", "crash-loop"}}, "gave up");
    EXPECT_TRUE(store.execution(id)->suspension.is_null());
    EXPECT_EQ(store.events(0, 100, std::string("execution")).back().payload["error"]["code"], "crash-loop");
  }
  sqlite3* h = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &h), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(h, "DROP INDEX runs_by_campaign; DROP INDEX runs_by_status; ALTER TABLE runs DROP COLUMN list_summary; ALTER TABLE executions DROP COLUMN suspension; PRAGMA user_version = 6;", nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(h);
  Store migrated(path);
  ASSERT_TRUE(migrated.execution(id).has_value());
  EXPECT_EQ(migrated.execution(id)->status, ExecutionStatus::finished_error);
  EXPECT_TRUE(migrated.execution(id)->suspension.is_null());
}

// GET /v1/executions: newest first, keyset pages, filtered by any of several statuses and by campaign.
TEST(Store, ExecutionsPageNewestFirstFilteredByStatusesAndCampaign) {
  using colorlab::protocol::ExecutionStatus;
  TempDir dir;
  Store store(dir / "colorlab.db");
  std::vector<std::string> all, spot_ended;
  for (int i = 0; i < 8; ++i) {
    auto run = luminance_run();
    if (i % 4 == 0) run.campaign = "frame-average";
    auto id = store.create_execution(run).execution.id;
    all.push_back(id);
    if (i % 4 != 0 && i % 2 == 1) {
      store.update_execution(id, ExecutionStatus::aborted, 0.5, "reading 2");
      spot_ended.push_back(id);
    } else if (i % 4 != 0) {
      store.update_execution(id, ExecutionStatus::finished_ok, 1, "done");
      spot_ended.push_back(id);
    }
  }
  auto collect = [&](const colorlab::store::ExecutionFilter& f, unsigned limit) {
    std::vector<std::string> ids;
    std::optional<std::string> cursor;
    int pages = 0;
    do {
      auto page = store.executions(limit, cursor, f);
      EXPECT_LE(page.items.size(), limit);
      for (const auto& e : page.items) {
        if (!f.campaign.empty()) {
          EXPECT_EQ(e.campaign, f.campaign);
        }
        if (!f.statuses.empty()) {
          EXPECT_NE(std::find(f.statuses.begin(), f.statuses.end(), e.status), f.statuses.end());
        }
        ids.push_back(e.id);
      }
      cursor = page.next_cursor;
      if (++pages > 20) break;  // a cursor that never ends the listing
    } while (cursor);
    return ids;
  };
  std::reverse(all.begin(), all.end());
  std::reverse(spot_ended.begin(), spot_ended.end());
  EXPECT_EQ(collect({}, 3), all);  // 3 pages of 3, 3, 2: each once, newest first
  EXPECT_EQ(collect({}, 8), all);  // exactly one page: no cursor to an empty page
  EXPECT_EQ(collect({{}, "frame-average"}, 1).size(), 2u);
  EXPECT_EQ(collect({{ExecutionStatus::aborted, ExecutionStatus::finished_ok}, "luminance-spot"}, 2), spot_ended);
  EXPECT_EQ(collect({{ExecutionStatus::aborted}, ""}, 2).size(), 4u);
  EXPECT_EQ(collect({{ExecutionStatus::waiting}, ""}, 5).size(), 2u);  // the frame-average ones, never started
  EXPECT_TRUE(collect({{ExecutionStatus::running}, ""}, 5).empty());
  EXPECT_TRUE(collect({{}, "no-such-campaign"}, 5).empty());
  auto exact = store.executions(8, std::nullopt);
  EXPECT_FALSE(exact.next_cursor);
  ASSERT_EQ(exact.items.size(), 8u);
  EXPECT_EQ(exact.items.front().to_json(), store.execution(all.front())->to_json());
  EXPECT_THROW(store.executions(3, std::string("abc")), Error);
}

// Issue 27: a step committed through a second writer's connection (the daemon's committer thread) is the same
// whole step, ordered with the first writer's events by SQLite's write lock; a read snapshot on the first
// connection does not see it until the snapshot ends (an event stream's snapshot agrees with its seq).
TEST(Store, ASecondWriterCommitsWholeStepsInEventOrderAndAReadSnapshotKeepsItsView) {
  TempDir dir;
  Store store(dir / "colorlab.db");
  Store second(dir / "colorlab.db", Store::SecondWriter{});
  auto e = scripted_execution(store);
  StepRecord step;
  step.journal.push_back({0, "meter.measure", json::array(), {{"luminance", 245.5}}});
  step.measurements.push_back({"reading/0", "ls110", true, "luminance", 245.5, "cd/m2", nullptr});
  step.progress = 0.5;
  step.step = "reading/0";
  const std::int64_t before = store.last_event_seq();
  {
    const auto view = store.read_snapshot();
    EXPECT_EQ(store.last_event_seq(), before);
    second.commit_step(e, step);
    // Committed and durable on the other connection, not seen inside the snapshot.
    EXPECT_EQ(store.last_event_seq(), before);
    EXPECT_EQ(store.measurements(e.run_id).size(), 0u);
  }
  EXPECT_EQ(store.measurements(e.run_id).size(), 1u);
  EXPECT_EQ(store.execution(e.id)->steps_committed, 1);
  const std::int64_t step_event = store.last_event_seq();
  EXPECT_GT(step_event, before);
  // The first writer's next event comes after the second writer's step.
  store.append_event("execution", {{"execution_id", e.id}, {"requested", "pause"}});
  const auto events = store.events(before, 100, std::nullopt);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].topic, "progress");
  EXPECT_EQ(events[1].topic, "execution");
  // A repeated step is refused whole there too.
  EXPECT_THROW(second.commit_step(e, step), colorlab::Error);
  EXPECT_EQ(store.measurements(e.run_id).size(), 1u);
}

// The one read-transaction type (store::ReadTransaction, also Store::read_snapshot): inside a caller's transaction
// it joins it — no nested BEGIN, which SQLite refuses, and no COMMIT of the caller's writes when it ends.
TEST(Store, AReadTransactionInsideACallersTransactionJoinsIt) {
  TempDir dir;
  colorlab::store::Database db((dir / "t.db").string(), false);
  db.exec("CREATE TABLE t(x INTEGER)");
  colorlab::store::Transaction tx(db);
  db.exec("INSERT INTO t VALUES (1)");
  {
    colorlab::store::ReadTransaction read(db);
    auto st = db.prepare("SELECT count(*) FROM t");
    ASSERT_TRUE(st.step());
    EXPECT_EQ(st.int64(0), 1) << "the read does not see its caller's own write";
  }
  EXPECT_EQ(sqlite3_get_autocommit(db.handle()), 0) << "the read transaction ended its caller's transaction";
  tx.commit();
  EXPECT_NE(sqlite3_get_autocommit(db.handle()), 0);
}
