// Heavy work is off colorlabd's io thread (issue 27): while a dry run's characterization fit is held
// on the worker pool (the COLORLAB_TEST_WORKER_LATCH hook), every other route still answers — the
// root, the control lock, the queue, the instruments, a campaign start, an operator's answer, pause
// and resume. Before the pool, the fit ran on the io thread and all of them waited behind it. Then the
// job is released and both the dry run's report and the execution's own fit arrive. No timing
// thresholds: the hold is a latch the test releases, and every wait is bounded with a message.
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <thread>

#include <gtest/gtest.h>

#include "resume_support.hpp"

using namespace colorlab;
using namespace colorlab::testing;
using nlohmann::json;

namespace {

// An operator's answer, then a characterization of 36 synthetic patches: a camera whose 16-bit
// values are a gamma of a linear mix of the patches' XYZ (so every approach has something to fit).
constexpr const char* kHoldFit = R"lua(
return {
  description = "test: an operator's answer, then a characterization fit on the worker pool",
  needs = {},
  parameters = {},
  run = function(p)
    local a = lab.operator.request { action = "test_confirm_fit", prompt = "fit now?", options = { "fit" },
                                     default = "fit", timeout_s = 100000 }
    local function f(t) if t > 216 / 24389 then return t ^ (1 / 3) end return (24389 / 27 * t + 16) / 116 end
    local ids, rgb, xyz, lab_ = {}, {}, {}, {}
    for r = 1, 4 do for g = 1, 3 do for b = 1, 3 do
      local k = #ids + 1
      local R, G, B = r / 4, g / 3, b / 3
      local X = 0.43 * R + 0.39 * G + 0.14 * B
      local Y = 0.22 * R + 0.72 * G + 0.06 * B
      local Z = 0.01 * R + 0.10 * G + 0.72 * B
      ids[k] = "P" .. k
      xyz[k] = { 100 * X, 100 * Y, 100 * Z }
      local fx, fy, fz = f(X / 0.9642), f(Y), f(Z / 0.8249)
      lab_[k] = { 116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz) }
      rgb[k] = { 65535 * R ^ (1 / 2.2), 65535 * G ^ (1 / 2.2), 65535 * B ^ (1 / 2.2) }
    end end end
    local fit = lab.analysis.characterize({ ids = ids, values = rgb, format = "tiff16", bits = 16 },
                                          { ids = ids, Lab = lab_, XYZ = xyz }, { cv = "k10" })
    return { answer = a.answer, best = fit.best_approach, patches = fit.patches }
  end,
}
)lua";

template <class Pred>
bool wait_for(Pred pred, std::chrono::seconds bound = std::chrono::seconds(120)) {
  const auto deadline = std::chrono::steady_clock::now() + bound;
  while (!pred()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

// The daemon inherits the hook from the test's environment, set only while it starts.
struct LatchEnvironment {
  explicit LatchEnvironment(const std::filesystem::path& latch) { ::setenv("COLORLAB_TEST_WORKER_LATCH", latch.c_str(), 1); }
  ~LatchEnvironment() { ::unsetenv("COLORLAB_TEST_WORKER_LATCH"); }
};

}  // namespace

TEST(WorkerPool, EveryRouteAnswersWhileAFitIsHeldOnThePool) {
  TempDir dir;
  auto config = write_daemon_config(dir.path(), 200, 5);
  write_campaign(dir.path(), "hold-fit.lua", kHoldFit);
  const auto latch = dir / "latch";
  std::unique_ptr<DaemonProcess> daemon;
  {
    LatchEnvironment hook(latch);
    daemon = std::make_unique<DaemonProcess>(dir / "state", config, dir / "colorlabd.log");
  }
  auto api = api_for(*daemon);

  // An execution waits for its operator; then a dry run's fit is held on the pool.
  json execution = api.post("/v1/executions", {{"campaign", "hold-fit"}, {"params", json::object()}});
  const std::string id = execution["id"];
  json pending;
  ASSERT_TRUE(wait_for([&] {
    auto items = api.get("/v1/requests")["items"];
    if (!items.empty()) pending = items[0];
    return !items.empty();
  })) << "the execution never asked its operator";

  auto dry = std::async(std::launch::async, [&] {
    auto own = api_for(*daemon);  // its own connection: this request waits for the fit
    return own.post("/v1/executions", {{"campaign", "hold-fit"}, {"params", json::object()}, {"dry_run", true}});
  });
  ASSERT_TRUE(wait_for([&] { return std::filesystem::exists(latch.string() + ".held"); }))
      << "the dry run's fit never reached the worker pool";
  ASSERT_EQ(dry.wait_for(std::chrono::seconds(0)), std::future_status::timeout) << "the dry run answered before its fit";

  // While the fit is held: everything served on the io thread answers.
  EXPECT_TRUE(api.get("/v1").is_object());
  EXPECT_TRUE(api.get("/v1/control").is_object());
  EXPECT_TRUE(api.get("/v1/queue").is_object());
  EXPECT_TRUE(api.get("/v1/instruments").contains("items"));
  EXPECT_EQ(api.get("/v1/executions/" + id)["status"], "running");
  const json answered = api.post("/v1/requests/" + pending["id"].get<std::string>(), {{"answer", "fit"}});
  EXPECT_TRUE(answered.is_object()) << answered.dump();
  EXPECT_TRUE(api.post("/v1/executions/" + id + "/pause", json::object()).is_object());
  EXPECT_TRUE(api.post("/v1/executions/" + id + "/resume", json::object()).is_object());
  ASSERT_EQ(dry.wait_for(std::chrono::seconds(0)), std::future_status::timeout) << "the held fit was let go";

  // Released: the dry run's report arrives, and the execution's own fit (queued behind) finishes it.
  std::ofstream(latch.string() + ".release") << "go\n";
  ASSERT_EQ(dry.wait_for(std::chrono::seconds(240)), std::future_status::ready) << "the dry run never answered";
  const json report = dry.get();
  EXPECT_TRUE(report["ok"].get<bool>()) << report.dump(2);
  EXPECT_TRUE(report["finished"].get<bool>()) << report.dump(2);
  const json done = wait_terminal(api, id, std::chrono::seconds(240));
  ASSERT_EQ(done["status"], "finished_ok") << done.dump(2);
  json run = api.get("/v1/runs/" + done["run_id"].get<std::string>());
  const json& result = run["summary"]["script"];
  EXPECT_EQ(result["answer"], "fit") << run.dump(2);
  EXPECT_EQ(result["patches"], 36) << run.dump(2);
  EXPECT_TRUE(result["best"].is_string()) << run.dump(2);
}
