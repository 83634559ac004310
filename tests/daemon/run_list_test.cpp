// GET /v1/runs costs the same however many runs are kept (issue 27: its p99 rose night over night in the
// soak). Checked by what SQLite says it will do, not by a time: every page of the list, filtered or not,
// is a walk down the primary key or an index of its filter (no scan of the table, no sort, nothing read
// from the measurements per run), and a listed run carries its summary without the campaign script's own
// result (unbounded in size: a characterization, a grid's values), which one run's document keeps.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <string>
#include <vector>

#include "colorlab/store/store.hpp"
#include "colorlab/testing/temp_dir.hpp"

using colorlab::protocol::ExecutionStatus;
using colorlab::store::NewRun;
using colorlab::store::RunFilter;
using colorlab::store::Store;
using colorlab::testing::TempDir;
using nlohmann::json;

namespace {

// The detail column of EXPLAIN QUERY PLAN for the list's SQL.
std::vector<std::string> query_plan(const std::filesystem::path& db, const std::string& sql) {
  sqlite3* h = nullptr;
  EXPECT_EQ(sqlite3_open_v2(db.c_str(), &h, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  sqlite3_stmt* st = nullptr;
  std::vector<std::string> out;
  if (sqlite3_prepare_v2(h, ("EXPLAIN QUERY PLAN " + sql).c_str(), -1, &st, nullptr) != SQLITE_OK) {
    ADD_FAILURE() << sqlite3_errmsg(h) << " in " << sql;
  } else {
    while (sqlite3_step(st) == SQLITE_ROW) out.emplace_back(reinterpret_cast<const char*>(sqlite3_column_text(st, 3)));
  }
  sqlite3_finalize(st);
  sqlite3_close(h);
  return out;
}

std::string joined(const std::vector<std::string>& lines) {
  std::string s;
  for (const auto& l : lines) s += l + "\n";
  return s;
}

// `n` finished runs alternating between two campaigns, each with a script result of ~20 kB.
void keep_runs(Store& store, int n) {
  json big = json::array();
  for (int i = 0; i < 1000; ++i) big.push_back(i * 0.125);
  for (int i = 0; i < n; ++i) {
    NewRun r;
    r.campaign = i % 2 ? "cabinet-grid" : "luminance-spot";
    r.params = json::object();
    r.simulated = true;
    r.instruments = json::array();
    auto e = store.create_execution(r).execution;
    store.finish_execution(e, i % 3 ? ExecutionStatus::finished_ok : ExecutionStatus::finished_error, "done",
                           {{"measurements", {{"luminance", {{"count", 2}}}}}, {"script", {{"values", big}}}}, nullptr, "");
  }
}

}  // namespace

TEST(RunList, EveryPageWalksAnIndexNeverTheWholeTableNorTheMeasurements) {
  TempDir dir;
  {
    Store store(dir / "colorlab.db");
    keep_runs(store, 60);
  }
  const std::vector<std::pair<RunFilter, std::string>> cases = {
      {{}, "INTEGER PRIMARY KEY"},
      {{"cabinet-grid", ""}, "INDEX runs_by_campaign"},
      {{"", "finished_ok"}, "INDEX runs_by_status"},
      {{"cabinet-grid", "finished_ok"}, "INDEX runs_by_"},
  };
  for (const auto& [filter, walk] : cases) {
    const auto sql = colorlab::store::run_list_sql(filter);
    const auto plan = query_plan(dir / "colorlab.db", sql);
    const auto text = joined(plan);
    SCOPED_TRACE("filter campaign='" + filter.campaign + "' status='" + filter.status + "'\n" + sql + "\n" + text);
    ASSERT_EQ(plan.size(), 1u) << "one step over runs, no subquery";
    EXPECT_EQ(plan[0].rfind("SEARCH runs USING ", 0), 0u) << "not a search of an index";
    EXPECT_NE(plan[0].find(walk), std::string::npos);
    EXPECT_EQ(text.find("SCAN"), std::string::npos) << "a scan of every run";
    EXPECT_EQ(text.find("TEMP B-TREE"), std::string::npos) << "a sort of every matching run";
    EXPECT_EQ(text.find("measurements"), std::string::npos) << "per-run work on the measurements";
  }
}

TEST(RunList, AListedRunLeavesOutTheScriptResultWhichItsOwnDocumentKeeps) {
  TempDir dir;
  Store store(dir / "colorlab.db");
  keep_runs(store, 9);
  const auto page = store.runs(50, std::nullopt);
  ASSERT_EQ(page.runs.size(), 9u);
  for (const auto& r : page.runs) {
    EXPECT_TRUE(r.summary.contains("measurements")) << r.summary.dump();
    EXPECT_FALSE(r.summary.contains("script")) << "the list carried a script result";
    const auto whole = store.run(r.id);
    ASSERT_TRUE(whole.has_value());
    EXPECT_EQ(whole->summary["script"]["values"].size(), 1000u);
  }
  // The filters still page through exactly their runs, newest first.
  std::vector<std::int64_t> seqs;
  std::optional<std::string> cursor;
  do {
    auto p = store.runs(2, cursor, {"cabinet-grid", "finished_ok"});
    for (const auto& r : p.runs) {
      EXPECT_EQ(r.campaign, "cabinet-grid");
      EXPECT_EQ(r.status, "finished_ok");
      seqs.push_back(r.seq);
    }
    cursor = p.next_cursor;
  } while (cursor);
  // Runs 1, 5, 7 of 0..8 are odd (cabinet-grid) and not a multiple of 3 (finished_ok): seq = i + 1.
  EXPECT_EQ(seqs, (std::vector<std::int64_t>{8, 6, 2}));
}

TEST(RunList, MigrationFillsTheListSummaryOfRunsKeptBefore) {
  TempDir dir;
  const auto path = dir / "colorlab.db";
  {
    Store store(path);
    keep_runs(store, 3);
  }
  // Back to schema 7: no list column, no indexes, as a database written before them.
  sqlite3* h = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &h), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(h, "DROP INDEX runs_by_campaign; DROP INDEX runs_by_status; ALTER TABLE runs DROP COLUMN list_summary; "
                            "PRAGMA user_version = 7;",
                         nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(h);
  Store migrated(path);
  const auto page = migrated.runs(10, std::nullopt);
  ASSERT_EQ(page.runs.size(), 3u);
  for (const auto& r : page.runs) {
    EXPECT_EQ(r.summary["measurements"]["luminance"]["count"], 2) << r.summary.dump();
    EXPECT_FALSE(r.summary.contains("script"));
  }
}
