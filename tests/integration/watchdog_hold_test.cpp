// systemd's watchdog keeps hearing from colorlabd while its work is held (issue 27): the pings (WATCHDOG=1 at
// half WatchdogSec) come from the io thread, so a step's commit held in its fsync (the fault shim's HOLD) or a
// fit held on the worker pool (COLORLAB_TEST_WORKER_LATCH) must not stop them — before the committer and the
// pool, either ran on the io thread and systemd would have killed a daemon busy with a long fit. The test plays
// systemd (a NOTIFY_SOCKET it reads). No timing thresholds: the holds are the test's switches; it asks for three
// pings while each is held, each waited for at most 10 s (WatchdogSec 0.4 s here: a ping every 0.2 s).
#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <thread>

#include <gtest/gtest.h>

#include "colorlab/testing/notify_socket.hpp"
#include "disk_fault_support.hpp"
#include "resume_support.hpp"
#include "scoped_env.hpp"

using namespace colorlab;
using namespace colorlab::testing;
using nlohmann::json;

namespace {

// A characterization of 36 synthetic patches, so a dry run reaches a fit on the worker pool.
constexpr const char* kFit = R"lua(
return {
  description = "test: a characterization fit on the worker pool",
  needs = {},
  parameters = {},
  run = function(p)
    local ids, rgb, xyz, lab_ = {}, {}, {}, {}
    local function f(t) if t > 216 / 24389 then return t ^ (1 / 3) end return (24389 / 27 * t + 16) / 116 end
    for r = 1, 4 do for g = 1, 3 do for b = 1, 3 do
      local k = #ids + 1
      local R, G, B = r / 4, g / 3, b / 3
      local X, Y, Z = 0.43 * R + 0.39 * G + 0.14 * B, 0.22 * R + 0.72 * G + 0.06 * B, 0.01 * R + 0.10 * G + 0.72 * B
      ids[k] = "P" .. k
      xyz[k] = { 100 * X, 100 * Y, 100 * Z }
      local fx, fy, fz = f(X / 0.9642), f(Y), f(Z / 0.8249)
      lab_[k] = { 116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz) }
      rgb[k] = { 65535 * R ^ (1 / 2.2), 65535 * G ^ (1 / 2.2), 65535 * B ^ (1 / 2.2) }
    end end end
    local fit = lab.analysis.characterize({ ids = ids, values = rgb, format = "tiff16", bits = 16 },
                                          { ids = ids, Lab = lab_, XYZ = xyz }, { cv = "k10" })
    return { best = fit.best_approach }
  end,
}
)lua";

template <class Pred>
bool wait_for(Pred pred, std::chrono::seconds bound = std::chrono::seconds(60)) {
  const auto deadline = std::chrono::steady_clock::now() + bound;
  while (!pred()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

// Throws away what the daemon sent so far: the pings counted next were sent after this moment.
void drain(NotifySocket& systemd) {
  // 1 ms, not 0: a zero SO_RCVTIMEO would wait for ever.
  while (!systemd.receive(std::chrono::milliseconds(1)).empty()) {
  }
}

// WATCHDOG=1 datagrams among the next messages, until `wanted` or a 10 s silence.
int pings(NotifySocket& systemd, int wanted) {
  int n = 0;
  while (n < wanted) {
    const std::string m = systemd.receive(std::chrono::seconds(10));
    if (m.empty()) break;
    if (m.find("WATCHDOG=1") != std::string::npos) ++n;
  }
  return n;
}

}  // namespace

TEST(WatchdogWhileHeld, PingsGoOnWhileACommitIsHeldInItsSyncAndWhileAFitIsHeldOnThePool) {
  TempDir dir;
  NotifySocket systemd(dir / "notify.sock");
  DiskFaults faults(dir / "state", dir / "fault");
  write_campaign(dir.path(), "fit.lua", kFit);
  const auto latch = dir / "latch";
  std::ofstream(latch.string() + ".release") << "go\n";  // the pool's jobs pass until part 2 holds them
  std::unique_ptr<DaemonProcess> daemon;
  {
    ScopedEnv env{
        {"NOTIFY_SOCKET", systemd.path().string()},
        {"WATCHDOG_USEC", "400000"},
        {"COLORLAB_TEST_WORKER_LATCH", latch.string()},
    };
    daemon = faults.start(write_daemon_config(dir.path(), 100, 3));
  }
  auto api = api_for(*daemon);
  ASSERT_EQ(pings(systemd, 1), 1) << "no watchdog ping at all (is WATCHDOG_USEC honoured?)";

  // 1. A step's commit held in its fsync.
  const json e = api.post("/v1/executions", {{"campaign", "luminance-spot"}, {"params", {{"readings", 6}, {"interval_s", 5}}}});
  const std::string id = e["id"];
  ASSERT_TRUE(wait_for([&] { return api.get("/v1/executions/" + id)["steps_committed"].get<std::int64_t>() >= 1; }))
      << "the campaign committed no step within 60 s";
  faults.fail("HOLD");
  const auto held = (dir / "fault").string() + ".held";
  ASSERT_TRUE(wait_for([&] { return std::filesystem::exists(held); })) << "no commit reached its sync within 60 s";
  const auto steps_held = api.get("/v1/executions/" + id)["steps_committed"].get<std::int64_t>();
  drain(systemd);
  EXPECT_EQ(pings(systemd, 3), 3) << "the watchdog went quiet while a commit was held";
  EXPECT_EQ(api.get("/v1/executions/" + id)["steps_committed"].get<std::int64_t>(), steps_held)
      << "the hold ended before the pings were counted: they prove nothing";
  faults.mend();
  const json done = wait_terminal(api, id);
  ASSERT_EQ(done["status"], "finished_ok") << done.dump(2);

  // 2. A fit held on the worker pool (a dry run's: it answers only once the fit is done).
  std::filesystem::remove(latch.string() + ".release");
  std::filesystem::remove(latch.string() + ".held");
  auto dry = std::async(std::launch::async, [&] {
    auto own = api_for(*daemon);
    return own.post("/v1/executions", {{"campaign", "fit"}, {"params", json::object()}, {"dry_run", true}});
  });
  ASSERT_TRUE(wait_for([&] { return std::filesystem::exists(latch.string() + ".held"); }))
      << "the dry run's fit never reached the worker pool within 60 s";
  drain(systemd);
  EXPECT_EQ(pings(systemd, 3), 3) << "the watchdog went quiet while a fit was held on the pool";
  EXPECT_EQ(dry.wait_for(std::chrono::seconds(0)), std::future_status::timeout)
      << "the fit was let go before the pings were counted: they prove nothing";
  std::ofstream(latch.string() + ".release") << "go\n";
  ASSERT_EQ(dry.wait_for(std::chrono::seconds(120)), std::future_status::ready) << "the dry run never answered";
  EXPECT_TRUE(dry.get()["ok"].get<bool>());
}
