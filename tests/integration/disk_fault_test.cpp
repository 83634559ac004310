// A full disk (ENOSPC) and a failing one (EIO) under the state directory, injected without privileges by
// the fault shim while colorlabd runs (issue 27): during a measurement's commit, a kept frame's blob write
// and a report. The run suspends with the cause in the API, goes on by itself once the disk takes writes
// again, loses nothing it had committed, and nothing half-written is ever served.
#include <cmath>
#include <fstream>
#include <set>
#include <thread>

#include <gtest/gtest.h>

#include "colorlab/sim/control_channel.hpp"
#include "disk_fault_support.hpp"
#include "last_step_campaign.hpp"
#include "resume_support.hpp"

using namespace colorlab;
using namespace colorlab::testing;
using nlohmann::json;

namespace {

constexpr double kTimeScale = 100;
// Lab seconds: 0.2 s of wall time at the time scale (the engine's floor) between attempts to commit.
const char* kSuspendConfig = "[campaigns]\nsuspend_retry_s = 20\nsuspend_settle_s = 20\n";

json sim_truth(const DaemonProcess& daemon) {
  json endpoint = json::parse(std::ifstream(daemon.state_dir() / "colorlabd.endpoint"));
  return sim::send_control_command(endpoint.at("simulator_control").get<std::string>(), {{"cmd", "truth"}});
}

json run_of(const client::ApiClient& api, const json& execution) {
  return client::fetch_run(api, execution["run_id"].get<std::string>());
}

void wait_for_measurements(const client::ApiClient& api, const json& execution, std::size_t n) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (run_of(api, execution)["measurements"].size() < n && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_GE(run_of(api, execution)["measurements"].size(), n) << "the campaign did not get going within 60 s";
}

// Polls until the execution is suspended and returns its reason; "" (and a failure) if it never was.
std::string wait_suspended(const client::ApiClient& api, const json& execution) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  json e;
  while (std::chrono::steady_clock::now() < deadline) {
    e = api.get("/v1/executions/" + execution["id"].get<std::string>());
    if (e["status"] == "suspended") return e.value("reason", std::string("(no reason)"));
    if (e["status"] != "running" && e["status"] != "waiting") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ADD_FAILURE() << "the execution was not suspended within 60 s: " << e.dump(2);
  return "";
}

// Every execution event, oldest first (the log is paged by sequence number).
std::vector<json> execution_events(const client::ApiClient& api) {
  std::vector<json> out;
  std::int64_t after = 0;
  for (;;) {
    const json page = api.get("/v1/events?topic=execution&limit=300&after=" + std::to_string(after));
    if (page["items"].empty()) return out;
    for (const auto& ev : page["items"]) out.push_back(ev);
    after = page["items"].back()["seq"].get<std::int64_t>();
  }
}

bool resumed_after_storage(const client::ApiClient& api) {
  for (const auto& ev : execution_events(api)) {
    const auto how = ev["payload"].value("resumed_after_suspension", json());
    if (how.is_object() && how.value("condition", std::string()) == "storage") return true;
  }
  return false;
}

// Regular files anywhere under `dir` (a blob store's temporaries, half-written or not, count).
std::vector<std::filesystem::path> files_under(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> out;
  if (!std::filesystem::exists(dir)) return out;
  for (const auto& f : std::filesystem::recursive_directory_iterator(dir)) {
    if (f.is_regular_file()) out.push_back(f.path());
  }
  return out;
}

std::string sha256_of(const std::string& bytes, const std::filesystem::path& scratch) {
  std::ofstream(scratch, std::ios::binary) << bytes;
  std::string out = shell_output("sha256sum '" + scratch.string() + "'");
  return out.substr(0, out.find(' '));
}

// luminance-spot through a disk that refuses its commits: the readings taken meanwhile wait in memory,
// the execution is suspended (the cause in GET /v1/executions/{id}), and once the disk takes writes the
// run completes with every step once, in order, each reading the simulator's truth within its noise, and
// the rows committed before the fault unchanged.
void commit_through(const std::string& how, const std::string& cause_text) {
  TempDir dir;
  DiskFaults faults(dir / "state", dir / "fault");
  auto daemon = faults.start(write_daemon_config(dir.path(), kTimeScale, 3, kSuspendConfig));
  auto api = api_for(*daemon);
  constexpr int kReadings = 40;
  auto e = api.post("/v1/executions", {{"campaign", "luminance-spot"}, {"params", {{"readings", kReadings}, {"interval_s", 5}}}});
  wait_for_measurements(api, e, 3);
  faults.fail(how);
  const std::string reason = wait_suspended(api, e);
  EXPECT_EQ(reason.rfind("storage: ", 0), 0u) << reason;
  EXPECT_NE(reason.find(cause_text), std::string::npos) << reason;
  // Held while the disk refuses: neither failed nor finished, and no row was added.
  const json before = run_of(api, e)["measurements"];
  ASSERT_LT(before.size(), static_cast<std::size_t>(kReadings)) << "the fault came after the last reading";
  std::this_thread::sleep_for(std::chrono::milliseconds(600));  // three of the engine's attempts to commit
  EXPECT_EQ(api.get("/v1/executions/" + e["id"].get<std::string>())["status"], "suspended");
  EXPECT_EQ(run_of(api, e)["measurements"].size(), before.size());
  faults.mend();
  auto done = wait_terminal(api, e["id"]);
  ASSERT_EQ(done["status"], "finished_ok") << done.dump(2);
  EXPECT_TRUE(resumed_after_storage(api)) << "no resumed_after_suspension {condition: storage} in the event log";

  const json run = run_of(api, e);
  ASSERT_EQ(run["measurements"].size(), static_cast<std::size_t>(kReadings));
  for (std::size_t i = 0; i < before.size(); ++i) EXPECT_EQ(run["measurements"][i], before[i]) << "committed row " << i << " changed";
  const json truth = sim_truth(*daemon)["ls110"];
  const double l = truth["luminance"].get<double>(), sigma = truth["noise_sigma"].get<double>();
  for (int i = 0; i < kReadings; ++i) {
    const auto& m = run["measurements"][static_cast<std::size_t>(i)];
    EXPECT_EQ(m["step"], "reading/" + std::to_string(i));
    // 4 σ of the LS-110's noise plus the 1 % a lamp may still lack when found stable (suspend_test.cpp).
    EXPECT_NEAR(m["value"].get<double>(), l, 4 * sigma + 0.01 * l) << m["step"];
  }
  daemon->kill9();
  EXPECT_EQ(integrity_check(faults.state_dir()), "ok");
}

// The run's last step — committed once its script has ended, with no lab call after it — through a full disk: the
// run is suspended with the cause, as for any other step, and finishes with the step once there is room. (Before
// 2026-11-30 the engine ended the run there: the suspension it asked for could not be stored on the full disk, and
// the execution stayed "running" until the next start.)
TEST(DiskFaults, AFullDiskAtTheRunsLastStepSuspendsItUntilThereIsRoomAndTheStepIsKept) {
  TempDir dir;
  DiskFaults faults(dir / "state", dir / "fault");
  write_last_step_campaign(dir.path());
  auto daemon = faults.start(write_daemon_config(dir.path(), kTimeScale, 3, kSuspendConfig));
  auto api = api_for(*daemon);
  const json e = api.post("/v1/executions", {{"campaign", "last-step"}, {"params", json::object()}});
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (api.get("/v1/executions/" + e["id"].get<std::string>())["status"] != "running" &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  faults.fail("ENOSPC");
  const std::string reason = wait_suspended(api, e);
  EXPECT_EQ(reason.rfind("storage: ", 0), 0u) << reason;
  EXPECT_TRUE(run_of(api, e)["measurements"].empty()) << "a row of the refused step was stored";
  std::this_thread::sleep_for(std::chrono::milliseconds(600));  // three of the engine's attempts to commit
  EXPECT_EQ(api.get("/v1/executions/" + e["id"].get<std::string>())["status"], "suspended");
  faults.mend();
  const json done = wait_terminal(api, e["id"]);
  ASSERT_EQ(done["status"], "finished_ok") << done.dump(2);
  EXPECT_TRUE(resumed_after_storage(api)) << "no resumed_after_suspension {condition: storage} in the event log";
  const json rows = run_of(api, e)["measurements"];
  ASSERT_EQ(rows.size(), 1U);
  EXPECT_EQ(rows[0]["step"], "last");
  daemon->kill9();
  EXPECT_EQ(integrity_check(faults.state_dir()), "ok");
}

TEST(DiskFaults, AFullDiskDuringACommitSuspendsTheRunUntilThereIsRoomAndNothingIsLost) {
  commit_through("ENOSPC", "full");
}

TEST(DiskFaults, AnIoErrorDuringACommitSuspendsTheRunUntilTheDiskWritesAgainAndNothingIsLost) {
  commit_through("EIO", "I/O");
}

// frame-average on the simulated DSLR keeps its averaged frame, the first frame and a preview in the blob
// store. With only the blob store refusing writes, the capture that keeps them suspends the run; no file,
// whole or partial, is left in the store and no blob is listed; with room again the step is measured anew
// and each kept blob reads back whole (its bytes hash to its name, its length is the listed size).
// `where`: how far the blob store got first — a full disk refuses the new fan-out directory ("cannot
// create"); a failing one makes it but fails its parent's sync ("cannot sync directory"), and each retry while
// the run is suspended gets as far as a temporary file whose bytes are refused, which the store must remove.
void blobs_through(const std::string& how, const std::string& cause_text, const std::string& where) {
  TempDir dir;
  std::ofstream(dir / "lab.toml") << "[genicam]\nenabled = false\n[dslr]\nsize = [320, 214]\n";
  std::ofstream(dir / "colorlabd.toml") << "[simulator]\nenabled = true\ntime_scale = 200\nseed = 3\nconfig = \"lab.toml\"\n"
                                        << kSuspendConfig;
  DiskFaults faults(dir / "state", dir / "fault");
  auto daemon = faults.start(dir / "colorlabd.toml");
  auto api = api_for(*daemon);
  faults.fail(how + " blobs");
  auto e = api.post("/v1/executions", {{"campaign", "frame-average"}, {"params", {{"frames", 2}}}});
  const std::string reason = wait_suspended(api, e);
  EXPECT_EQ(reason.rfind("storage: ", 0), 0u) << reason;
  EXPECT_NE(reason.find(cause_text), std::string::npos) << reason;
  EXPECT_NE(reason.find("blobs"), std::string::npos) << reason;
  EXPECT_NE(reason.find(where), std::string::npos) << reason;
  const std::string blobs_of_run = "/v1/runs/" + e["run_id"].get<std::string>() + "/blobs";
  EXPECT_TRUE(api.get(blobs_of_run)["items"].empty());
  EXPECT_EQ(files_under(faults.state_dir() / "blobs"), std::vector<std::filesystem::path>{}) << "a half-kept blob was left";
  faults.mend();
  auto done = wait_terminal(api, e["id"]);
  ASSERT_EQ(done["status"], "finished_ok") << done.dump(2);
  EXPECT_TRUE(resumed_after_storage(api)) << "no resumed_after_suspension {condition: storage} in the event log";

  const json blobs = api.get(blobs_of_run)["items"];
  ASSERT_FALSE(blobs.empty()) << "frame-average kept nothing";
  std::set<std::string> kinds;
  for (const auto& b : blobs) {
    const std::string sha = b["sha256"];
    kinds.insert(b["kind"].get<std::string>());
    auto r = api.request("GET", "/v1/blobs/" + sha);
    ASSERT_EQ(r.status, 200) << sha;
    EXPECT_EQ(r.body.size(), b["size"].get<std::size_t>()) << sha;
    EXPECT_EQ(sha256_of(r.body, dir / "blob.bin"), sha) << "blob " << sha << " is not whole";
  }
  EXPECT_TRUE(kinds.count("average")) << blobs.dump();
  daemon->kill9();
  EXPECT_EQ(integrity_check(faults.state_dir()), "ok");
}

TEST(DiskFaults, AFullBlobStoreSuspendsTheCaptureAndEveryKeptBlobReadsBackWhole) {
  blobs_through("ENOSPC", "No space", "cannot create");
}

TEST(DiskFaults, AnIoErrorInTheBlobStoreSuspendsTheCaptureAndEveryKeptBlobReadsBackWhole) {
  blobs_through("EIO", "Input/output error", "cannot sync directory");
}

// A report asked for while the reports directory refuses writes fails with the cause and leaves only a
// half-written temporary file, never served; asked for again with room (after the daemon's next start: a failure is remembered for a minute,
// ReportService::Options::retry_after_failure), it is served whole.
TEST(DiskFaults, AReportOnAFullDiskFailsWithTheCauseAndIsNeverServedHalfWritten) {
  TempDir dir;
  DiskFaults faults(dir / "state", dir / "fault");
  const auto config = write_daemon_config(dir.path(), kTimeScale, 3, kSuspendConfig);
  auto daemon = faults.start(config);
  auto api = api_for(*daemon);
  const json run = run_to_end(api, "luminance-spot", {{"readings", 3}, {"interval_s", 1}});
  const std::string target = "/v1/runs/" + run["id"].get<std::string>() + "/report";
  faults.fail("ENOSPC reports");
  client::RawResponse r;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  do {
    r = api.request("GET", target);
    if (r.status == 202) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  } while (r.status == 202 && std::chrono::steady_clock::now() < deadline);
  ASSERT_EQ(r.status, 500) << "a report was served from a full disk: " << r.body.substr(0, 300);
  EXPECT_NE(r.body.find("No space left on device"), std::string::npos) << r.body;
  // The report module got as far as its temporary file (a full disk still creates files); never renamed,
  // it is never served.
  bool partial = false;
  for (const auto& f : files_under(faults.state_dir() / "reports")) {
    EXPECT_NE(f.extension(), ".html") << "a report file exists after the failure: " << f;
    partial = partial || f.extension() == ".tmp";
  }
  EXPECT_TRUE(partial) << "no half-written report: the test no longer exercises one";
  faults.mend();
  daemon->kill9();
  daemon.reset();
  daemon = faults.start(config);
  auto again = api_for(*daemon);
  const auto second = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  do {
    r = again.request("GET", target);
    if (r.status == 202) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  } while (r.status == 202 && std::chrono::steady_clock::now() < second);
  ASSERT_EQ(r.status, 200) << r.body.substr(0, 500);
  EXPECT_EQ(r.body.rfind("<!DOCTYPE html>", 0), 0u) << r.body.substr(0, 100);
  EXPECT_NE(r.body.find("</html>"), std::string::npos) << "the served report ends early";
  daemon->kill9();
}

}  // namespace
