// A step's commit is off colorlabd's io thread (issue 27): while a campaign step's commit is held in its
// fsync — by the fault shim's HOLD mode (tests/support/faultshim), without privileges — every route served
// on the io thread still answers, and nothing of the held step is visible yet: its rows and its progress
// event appear only once the sync has returned ("committed" means durable). Released, the run completes
// with every step once, in order, its progress events in commit order. Before the committer thread, the
// fsync ran on the io thread and each of these requests waited behind it. No timing thresholds: the hold
// is the test's switch, and every wait is bounded with a message.
#include <chrono>
#include <filesystem>
#include <thread>

#include <gtest/gtest.h>

#include "disk_fault_support.hpp"
#include "last_step_campaign.hpp"
#include "resume_support.hpp"

using namespace colorlab;
using namespace colorlab::testing;
using nlohmann::json;

namespace {

template <class Pred>
bool wait_for(Pred pred, std::chrono::seconds bound = std::chrono::seconds(60)) {
  const auto deadline = std::chrono::steady_clock::now() + bound;
  while (!pred()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

std::size_t stored_rows(const client::ApiClient& api, const std::string& run_id) {
  return client::fetch_run(api, run_id)["measurements"].size();
}

// The execution's progress events after `after`, oldest first.
std::vector<json> progress_events(const client::ApiClient& api, const std::string& execution_id, std::int64_t after) {
  std::vector<json> out;
  for (;;) {
    const json page = api.get("/v1/events?topic=progress&limit=300&after=" + std::to_string(after));
    if (page["items"].empty()) return out;
    for (const auto& ev : page["items"]) {
      if (ev["payload"].value("execution_id", std::string()) == execution_id) out.push_back(ev);
    }
    after = page["items"].back()["seq"].get<std::int64_t>();
  }
}

std::int64_t last_event_seq(const client::ApiClient& api) {
  std::int64_t after = 0;
  for (;;) {
    const json page = api.get("/v1/events?limit=300&after=" + std::to_string(after));
    if (page["items"].empty()) return after;
    after = page["items"].back()["seq"].get<std::int64_t>();
  }
}

}  // namespace

TEST(CommitOffIoThread, MainRoutesAnswerWhileAStepsSyncIsHeldAndTheStepAppearsOnlyOnceDurable) {
  TempDir dir;
  DiskFaults faults(dir / "state", dir / "fault");
  auto daemon = faults.start(write_daemon_config(dir.path(), 100, 3));
  auto api = api_for(*daemon);
  constexpr int kReadings = 12;
  const json e = api.post("/v1/executions",
                          {{"campaign", "luminance-spot"}, {"params", {{"readings", kReadings}, {"interval_s", 5}}}});
  const std::string id = e["id"], run_id = e["run_id"];
  ASSERT_TRUE(wait_for([&] { return stored_rows(api, run_id) >= 2; })) << "the campaign did not get going within 60 s";

  // The next sync under the state directory is held: a step's commit, the only writer while readings go on.
  faults.fail("HOLD");
  const auto held = std::filesystem::path(dir / "fault").string() + ".held";
  ASSERT_TRUE(wait_for([&] { return std::filesystem::exists(held); })) << "no step's commit reached its sync within 60 s";
  const std::size_t rows_held = stored_rows(api, run_id);
  const std::int64_t seq_held = last_event_seq(api);
  const std::int64_t steps_held = api.get("/v1/executions/" + id)["steps_committed"].get<std::int64_t>();

  // While it is held: the io thread's routes answer (each would wait for the sync if it ran there).
  EXPECT_TRUE(api.get("/v1").is_object());
  EXPECT_TRUE(api.get("/v1/control").is_object());
  EXPECT_TRUE(api.get("/v1/queue").is_object());
  EXPECT_TRUE(api.get("/v1/instruments").contains("items"));
  EXPECT_TRUE(api.get("/v1/requests").contains("items"));
  const json during = api.get("/v1/executions/" + id);
  EXPECT_EQ(during["status"], "running") << during.dump(2);
  // Nothing of the held step shows before its sync returns: not its rows, not its progress, not its event.
  EXPECT_EQ(during["steps_committed"].get<std::int64_t>(), steps_held);
  EXPECT_EQ(stored_rows(api, run_id), rows_held);
  EXPECT_TRUE(progress_events(api, id, seq_held).empty()) << "a progress event announced a step not yet durable";
  ASSERT_TRUE(std::filesystem::exists(held));

  faults.mend();
  const json done = wait_terminal(api, id);
  ASSERT_EQ(done["status"], "finished_ok") << done.dump(2);
  EXPECT_GT(done["steps_committed"].get<std::int64_t>(), steps_held) << "the held step never committed";
  const json run = client::fetch_run(api, run_id);
  ASSERT_EQ(run["measurements"].size(), static_cast<std::size_t>(kReadings));
  for (int i = 0; i < kReadings; ++i) {
    EXPECT_EQ(run["measurements"][static_cast<std::size_t>(i)]["step"], "reading/" + std::to_string(i));
  }
  // The progress events in commit order: the event log's seq follows the commits, measurements add up.
  const auto events = progress_events(api, id, 0);
  ASSERT_FALSE(events.empty());
  double progress = -1;
  std::size_t measured = 0;
  for (const auto& ev : events) {
    const double p = ev["payload"]["progress"].get<double>();
    EXPECT_GE(p, progress) << ev.dump();
    progress = p;
    measured += ev["payload"].value("measurements", std::size_t{0});
  }
  EXPECT_EQ(measured, static_cast<std::size_t>(kReadings));
  daemon->kill9();
  EXPECT_EQ(integrity_check(faults.state_dir()), "ok");
}

// A run's last step — committed when its script ends, with no lab call after it — is off the io thread too: before
// 2026-11-30 the engine committed it there, synchronously, and every main route waited for its fsync (up to 92 ms
// measured, docs/PERFORMANCE.md "The writers' wait for the lock").
TEST(CommitOffIoThread, MainRoutesAnswerWhileARunsLastStepIsHeldInItsSync) {
  TempDir dir;
  DiskFaults faults(dir / "state", dir / "fault");
  write_last_step_campaign(dir.path());
  auto daemon = faults.start(write_daemon_config(dir.path(), 100, 3));
  auto api = api_for(*daemon);
  const json e = api.post("/v1/executions", {{"campaign", "last-step"}, {"params", json::object()}});
  const std::string id = e["id"], run_id = e["run_id"];
  ASSERT_TRUE(wait_for([&] { return api.get("/v1/executions/" + id)["status"] == "running"; }))
      << "the run did not start within 60 s";

  faults.fail("HOLD");
  const auto held = std::filesystem::path(dir / "fault").string() + ".held";
  ASSERT_TRUE(wait_for([&] { return std::filesystem::exists(held); })) << "the last step's commit never reached its sync";
  EXPECT_TRUE(api.get("/v1").is_object());
  EXPECT_TRUE(api.get("/v1/control").is_object());
  EXPECT_TRUE(api.get("/v1/queue").is_object());
  const json during = api.get("/v1/executions/" + id);
  EXPECT_EQ(during["status"], "running") << "the run ended before its last step was durable: " << during.dump(2);
  EXPECT_EQ(stored_rows(api, run_id), 0U) << "the held step's row showed before its sync returned";
  ASSERT_TRUE(std::filesystem::exists(held));

  faults.mend();
  const json done = wait_terminal(api, id);
  ASSERT_EQ(done["status"], "finished_ok") << done.dump(2);
  EXPECT_EQ(stored_rows(api, run_id), 1U);
  daemon->kill9();
  EXPECT_EQ(integrity_check(faults.state_dir()), "ok");
}
