// The bench's side of shipping without any server (docs/fleet.md, "Lag"): the backlog colorlabd shows in
// GET /v1/shipping, and the end event every ended run gets when the store opens — runs an older colorlabd marked
// interrupted at start-up had none, and colorlab-ship only ever sees a run through its end event.
#include <gtest/gtest.h>

#include <unistd.h>

#include "colorlab/fleet/bench_reader.hpp"
#include "colorlab/store/ship_log.hpp"
#include "colorlab/store/sqlite.hpp"
#include "sim_bench.hpp"

namespace fs = std::filesystem;
using namespace colorlab;
using protocol::ExecutionStatus;

namespace {

std::int64_t end_events_of(const fs::path& db_path, const std::string& run_id) {
  store::Database db(db_path.string(), true);
  auto st = db.prepare(
      "SELECT count(*) FROM event_log WHERE topic = 'execution' AND json_extract(payload, '$.run_id') = ?1 AND "
      "json_extract(payload, '$.status') = 'interrupted' AND json_extract(payload, '$.recorded_at_open') = 1");
  st.bind(1, std::string_view(run_id));
  st.step();
  return st.int64(0);
}

TEST(FleetShipLog, EveryEndedRunGetsAnEndEventAndTheBacklogCountsIt) {
  const fs::path dir = fs::temp_directory_path() / ("colorlab-fleet-shiplog-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  std::string first, second, marked_now, marked_by_old_daemon;
  {
    fleet_test::SimBench bench(dir, "bench-l", 9);
    first = bench.run_campaign(ExecutionStatus::finished_ok, 5, 0);
    second = bench.run_campaign(ExecutionStatus::aborted, 5, 0);
    // Both left running without a stored script, as an old colorlabd's executions were when it stopped.
    marked_now = bench.run_campaign(ExecutionStatus::finished_ok, 5, 0, false);
    marked_by_old_daemon = bench.run_campaign(ExecutionStatus::finished_ok, 5, 0, false);
    store::Database db((dir / "colorlab.db").string(), true);
    const auto b = store::ShipLog(db).backlog(0);
    EXPECT_EQ(b.runs, 2);
    EXPECT_EQ(b.oldest_run_id, first);
    EXPECT_EQ(b.oldest_status, "finished_ok");
    EXPECT_FALSE(b.oldest_ended_at.empty());
  }
  const fs::path db_path = dir / "colorlab.db";
  {
    // What an older colorlabd did at start-up: the run finalised, no event.
    store::Database db(db_path.string(), false);
    db.exec("UPDATE runs SET status = 'interrupted', finished_at = '2026-01-02T03:04:05.000Z' WHERE id = '" +
            marked_by_old_daemon + "'");
  }
  fleet::BenchReader before(db_path);
  EXPECT_EQ(before.ended_after(0, 100).size(), 2u) << "without end events the two runs are invisible to the agent";

  std::int64_t second_end = 0;
  for (const auto& r : before.ended_after(0, 100)) {
    if (r.run_id == second) second_end = r.ended_event;
  }
  {
    store::Store reopened(db_path);  // as colorlabd opens it at start-up
    EXPECT_EQ(reopened.interrupted_at_open(), 1);
  }
  EXPECT_EQ(end_events_of(db_path, marked_now), 1);
  EXPECT_EQ(end_events_of(db_path, marked_by_old_daemon), 1);
  {
    store::Database db(db_path.string(), true);
    store::ShipLog log(db);
    const auto all = log.backlog(0);
    EXPECT_EQ(all.runs, 4);
    const auto after_second = log.backlog(second_end);
    EXPECT_EQ(after_second.runs, 2);
    // Recorded in the order the runs were created.
    EXPECT_EQ(after_second.oldest_run_id, marked_now);
    EXPECT_EQ(after_second.oldest_status, "interrupted");
    EXPECT_EQ(log.backlog(all.last_event).runs, 0);
    EXPECT_TRUE(log.backlog(all.last_event).oldest_run_id.empty());
  }
  {
    store::Store again(db_path);
  }
  EXPECT_EQ(end_events_of(db_path, marked_now), 1) << "a run's end event is recorded once";
  EXPECT_EQ(end_events_of(db_path, marked_by_old_daemon), 1);
  fleet::BenchReader after(db_path);
  auto ended = after.ended_after(0, 100);
  ASSERT_EQ(ended.size(), 4u);
  EXPECT_EQ(ended[2].run_id, marked_now);
  EXPECT_EQ(ended[2].status, "interrupted");
  EXPECT_EQ(ended[3].run_id, marked_by_old_daemon);
  EXPECT_EQ(ended[3].status, "interrupted");
  fs::remove_all(dir);
}

}  // namespace
