// Suspend, not fail, on a lab with two cameras: the one a call named is the one a suspension brings back. Its own
// executable because the simulated GigE camera needs the loopback (the ctest lock gigevision_loopback), which the
// other suspend tests (suspend_test.cpp) do not.
#include <chrono>
#include <thread>

#include <gtest/gtest.h>

#include "suspend_support.hpp"

using namespace colorlab;
using namespace colorlab::testing;
using namespace colorlab::testing::suspend;
using nlohmann::json;

// A lab with two cameras (the simulated GigE camera first, the DSLR second) and a script that names the DSLR.
constexpr const char* kNamedDslr = R"(return {
  description = "the DSLR's ISO, set again every 10 s",
  needs = { "camera" },
  parameters = { rounds = { type = "integer", default = 40, min = 1, max = 1000 } },
  run = function(p)
    for i = 1, p.rounds do
      lab.camera.configure{ camera = "dslr", iso = 100 }
      lab.record("set/" .. i, { quantity = "iso", value = 100, unit = "1" })
      lab.wait(10)
    end
    return {}
  end,
})";

TEST(SuspendNotFail, ACameraTheCallNamedThatGoesAwayIsTheOneBroughtBack) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), kTimeScale, 3, kSuspendConfig, true));
  write_campaign(dir.path(), "named_dslr.lua", kNamedDslr);
  auto api = api_for(daemon);
  auto e = api.post("/v1/executions", {{"campaign", "named_dslr"}, {"params", {{"rounds", 40}}}});
  wait_for_measurements(api, e, 3);
  control(daemon, {{"cmd", "fault"}, {"instrument", "dslr"}, {"faults", {{"disconnect", true}}}});
  std::string reason = wait_suspended(api, e, std::chrono::seconds(30));
  EXPECT_EQ(reason.rfind("instrument: ", 0), 0u) << reason;
  // Gone for 2 s of wall time, ten retry intervals: recovery keeps trying the DSLR and the run stays in the one
  // suspension. Reconnecting the other camera instead reported the condition cleared, and the call failed and
  // suspended the run again at every retry.
  std::this_thread::sleep_for(std::chrono::seconds(2));
  EXPECT_EQ(api.get("/v1/executions/" + e["id"].get<std::string>())["status"], "suspended");
  control(daemon, {{"cmd", "fault"}, {"instrument", "dslr"}, {"faults", {{"disconnect", false}}}});
  auto done = wait_terminal(api, e["id"], std::chrono::seconds(120));
  ASSERT_EQ(done["status"], "finished_ok") << done.dump(2);
  EXPECT_EQ(measurements_of(api, e), 40u);

  int suspensions = 0;
  json how;
  json log = api.get("/v1/events?topic=execution&limit=300");
  for (const auto& ev : log["items"]) {
    if (ev["payload"].value("suspended", false)) ++suspensions;
    if (ev["payload"].contains("resumed_after_suspension")) how = ev["payload"]["resumed_after_suspension"];
  }
  EXPECT_EQ(suspensions, 1) << log.dump();
  ASSERT_TRUE(how.is_object()) << log.dump();
  EXPECT_EQ(how["condition"], "instrument");
  EXPECT_EQ(how["instrument"], "dslr") << how.dump();
  daemon.kill9();
}
