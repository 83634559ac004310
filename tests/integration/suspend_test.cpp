// Suspend, not fail: each cause injected into a running execution — an instrument that stops
// answering (the simulator's LS-110 goes silent), a lamp that goes out (the simulator's cabinet
// drops D65 for a while), a lamp that drifts (D65's output sags and comes back) — suspends it with the
// right reason; it goes on by itself once the condition has cleared, and the run equals an undisturbed
// one: every step once, in order, every reading within the simulator's noise. The camera a call named, on a lab with
// two: suspend_camera_test.cpp. A disk that fills or fails: disk_fault_test.cpp, under the fault shim (no privileges
// needed).
#include <cmath>
#include <thread>

#include <gtest/gtest.h>

#include "suspend_support.hpp"

using namespace colorlab;
using namespace colorlab::testing;
using namespace colorlab::testing::suspend;
using nlohmann::json;

namespace {

// Every step exactly once, in order, each reading within 4 σ of the LS-110's noise (plus the 1 % a
// lamp may still be below full output when the stability criterion accepts it) of the spot's truth.
void expect_undisturbed(const json& run, const std::string& prefix, int first, int count, double truth, double sigma) {
  ASSERT_EQ(run["measurements"].size(), static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    const auto& m = run["measurements"][static_cast<std::size_t>(i)];
    EXPECT_EQ(m["step"], prefix + std::to_string(first + i));
    EXPECT_NEAR(m["value"].get<double>(), truth, 4 * sigma + 0.01 * truth) << m["step"];
  }
}

TEST(SuspendNotFail, AnInstrumentThatStopsAnsweringSuspendsTheRunUntilItIsBack) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), kTimeScale, 3, kSuspendConfig));
  auto api = api_for(daemon);
  auto e = api.post("/v1/executions", {{"campaign", "luminance-spot"}, {"params", {{"readings", 40}, {"interval_s", 5}}}});
  wait_for_measurements(api, e, 5);
  control(daemon, {{"cmd", "fault"}, {"instrument", "ls110"}, {"faults", {{"silent", true}}}});
  std::string reason = wait_suspended(api, e, std::chrono::seconds(60));
  EXPECT_EQ(reason.rfind("instrument: ", 0), 0u) << reason;
  // Still suspended while the meter stays silent: the run neither fails nor skips ahead.
  std::this_thread::sleep_for(std::chrono::seconds(1));
  EXPECT_EQ(api.get("/v1/executions/" + e["id"].get<std::string>())["status"], "suspended");
  auto stored = measurements_of(api, e);
  control(daemon, {{"cmd", "fault"}, {"instrument", "ls110"}, {"faults", {{"silent", false}}}});
  auto done = wait_terminal(api, e["id"]);
  ASSERT_EQ(done["status"], "finished_ok") << done.dump(2);
  EXPECT_LT(stored, 40u) << "the fault came too late to interrupt anything";
  json truth = control(daemon, {{"cmd", "truth"}});
  expect_undisturbed(colorlab::client::fetch_run(api, e["run_id"].get<std::string>()), "reading/", 0, 40,
                     truth["ls110"]["luminance"], truth["ls110"]["noise_sigma"]);
  // The suspension and its end are in the event log.
  bool suspended = false, resumed = false;
  json log = api.get("/v1/events?topic=execution&limit=300");
  for (const auto& ev : log["items"]) {
    suspended = suspended || ev["payload"].value("suspended", false);
    resumed = resumed || ev["payload"].contains("resumed_after_suspension");
  }
  EXPECT_TRUE(suspended) << log.dump();
  EXPECT_TRUE(resumed);
  daemon.kill9();
}

constexpr const char* kSteadyReadings = R"(return {
  description = "readings under D65, one every 10 s",
  needs = { "luminance_meter", "lamps" },
  parameters = { readings = { type = "integer", default = 30, min = 1, max = 1000 } },
  run = function(p)
    lab.lamps.select("D65")
    lab.dimmer.set(100)
    lab.wait_stable()
    for i = 1, p.readings do
      local r = lab.meter.measure()
      lab.record("r/" .. i, { quantity = "luminance", value = r.luminance, unit = r.unit, instrument = r.instrument })
      lab.wait(10)
    end
    return {}
  end,
})";

TEST(SuspendNotFail, ALampThatGoesOutSuspendsTheRunUntilItIsBackAndStable) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), kTimeScale, 3, kSuspendConfig));
  write_campaign(dir.path(), "steady.lua", kSteadyReadings);
  auto api = api_for(daemon);
  auto e = api.post("/v1/executions", {{"campaign", "steady"}, {"params", {{"readings", 30}}}});
  wait_for_measurements(api, e, 4);
  // Out for 200 lab seconds; it relights cold and must warm up again before readings go on.
  control(daemon, {{"cmd", "fault"}, {"instrument", "cabinet"}, {"faults", {{"lamp_dropout", {{"lamp", "D65"}, {"seconds", 200}}}}}});
  std::string reason = wait_suspended(api, e, std::chrono::seconds(30));
  EXPECT_EQ(reason.rfind("lamp: ", 0), 0u) << reason;
  auto done = wait_terminal(api, e["id"], std::chrono::seconds(120));
  ASSERT_EQ(done["status"], "finished_ok") << done.dump(2);
  json truth = control(daemon, {{"cmd", "truth"}});
  // No reading in the dark and none of a lamp still warming up: all equal the warm lamp's truth.
  expect_undisturbed(colorlab::client::fetch_run(api, e["run_id"].get<std::string>()), "r/", 1, 30, truth["ls110"]["luminance"],
                     truth["ls110"]["noise_sigma"]);
  daemon.kill9();
}

// CWF found stable with the meter at the floor's bright middle, then read at its dark back corner: the floor
// differs between spots by more than a dropout's bound at one aim, so a reading at another aim is held only to
// a cabinet gone nearly dark (SuspendPolicy::dropout_fraction_other_aim).
constexpr const char* kAimedElsewhere = R"(return {
  description = "CWF stable at the floor's middle, then readings at its back-left corner",
  needs = { "luminance_meter", "lamps" },
  parameters = { readings = { type = "integer", default = 30, min = 1, max = 1000 } },
  run = function(p)
    local function aim(row, col)
      lab.operator.request { action = "aim_meter", prompt = "aim", options = { "aimed" }, default = "aimed",
                             timeout_s = 60, details = { row = row, col = col } }
    end
    lab.lamps.select("CWF")
    lab.dimmer.set(100)
    aim(4, 9)
    lab.wait_stable()
    local r = lab.meter.measure()
    lab.record("middle", { quantity = "luminance", value = r.luminance, unit = r.unit, instrument = r.instrument })
    aim(7, 0)
    for i = 1, p.readings do
      r = lab.meter.measure()
      lab.record("corner/" .. i, { quantity = "luminance", value = r.luminance, unit = r.unit, instrument = r.instrument })
      lab.wait(10)
    end
    return {}
  end,
})";

TEST(SuspendNotFail, ADimSpotTheMeterWasAimedAtIsNotALampOutButADarkCabinetStillIs) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), kTimeScale, 3, kSuspendConfig));
  write_campaign(dir.path(), "aimed.lua", kAimedElsewhere);
  auto api = api_for(daemon);
  auto e = api.post("/v1/executions", {{"campaign", "aimed"}, {"params", {{"readings", 30}}}});
  wait_for_measurements(api, e, 4);
  json truth = control(daemon, {{"cmd", "truth"}});
  json run = colorlab::client::fetch_run(api, e["run_id"].get<std::string>());
  const double middle = run["measurements"][0]["value"].get<double>();
  const double corner = truth["ls110"]["luminance"].get<double>();
  // The premise: at the stable aim's bound (0.2) this spot would read as a lamp gone out.
  // The premise: held to the stable aim's bound (SuspendPolicy::dropout_fraction, 0.2) this spot would read as a
  // lamp gone out.
  ASSERT_LT(corner, 0.2 * middle) << "the simulated CWF floor is no longer that uneven";
  for (std::size_t i = 1; i < run["measurements"].size(); ++i) {
    EXPECT_NEAR(run["measurements"][i]["value"].get<double>(), corner, 4 * truth["ls110"]["noise_sigma"].get<double>() + 0.01 * corner);
  }
  EXPECT_EQ(api.get("/v1/executions/" + e["id"].get<std::string>())["status"], "running");
  const auto events = api.get("/v1/events?topic=execution&limit=300");  // held: see dry_run_test.cpp
  for (const auto& ev : events["items"]) {
    EXPECT_FALSE(ev["payload"].value("suspended", false)) << "the dim spot itself suspended the run: " << ev.dump();
  }
  // The lamp going out at that dim spot is still a dropout.
  control(daemon, {{"cmd", "fault"}, {"instrument", "cabinet"}, {"faults", {{"lamp_dropout", {{"lamp", "CWF"}, {"seconds", 200}}}}}});
  std::string reason = wait_suspended(api, e, std::chrono::seconds(30));
  EXPECT_EQ(reason.rfind("lamp: ", 0), 0u) << reason;
  auto done = wait_terminal(api, e["id"], std::chrono::seconds(120));
  ASSERT_EQ(done["status"], "finished_ok") << done.dump(2);
  daemon.kill9();
}

// The cabinet grid, reduced: one row of four spots, D65 at two dimmer levels, a minute of settling after
// each dimmer change so that a lamp's bracket at a spot (its first level, the other, the first again)
// spans two lab minutes.
const json kDriftGrid = {{"rows", 1}, {"cols", 4}, {"lamps", {"D65"}}, {"dimmer_levels", {100, 50}}, {"settle_s", 60}};

TEST(SuspendNotFail, ALampThatDriftsMidGridSuspendsItUntilTheLightIsStableAndTheSpotIsReadAgain) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), kTimeScale, 3, kSuspendConfig));
  auto api = api_for(daemon);
  auto e = api.post("/v1/executions", {{"campaign", "cabinet-grid"}, {"params", kDriftGrid}});
  // The first spot is stored (committed as the second spot's aim is asked for): the drift starts while the
  // meter is aimed at the second spot, before any of its readings.
  wait_for_measurements(api, e, 2);
  // An overheating tube: −3 % of its output per lab minute for four minutes, then back at the same rate.
  // The bracket at the second spot (two minutes) sees about 6 % and suspends the run; the light is stable
  // again only once it has come back (eight minutes), and the spot is read again.
  json drift = control(daemon, {
                                   {"cmd", "fault"},
                                   {"instrument", "cabinet"},
                                   {"faults", {{"lamp_drift", {{"lamp", "D65"}, {"rate_pct_per_min", -3}, {"seconds", 240}, {"then", "return"}}}}},
                               });
  EXPECT_EQ(measurements_of(api, e), 2u) << "the drift came too late: the second spot was read before it";
  std::string reason = wait_suspended(api, e, std::chrono::seconds(30));
  EXPECT_EQ(reason.rfind("lamp: ", 0), 0u) << reason;
  EXPECT_NE(reason.find("the light drifted"), std::string::npos) << reason;
  EXPECT_NE(reason.find("[device lamp:drift]"), std::string::npos) << reason;
  auto done = wait_terminal(api, e["id"], std::chrono::seconds(60));
  ASSERT_EQ(done["status"], "finished_ok") << done.dump(2);

  // The resumption says what the light did: the cause, the level it settled at and how far that is from
  // what the spot's first reading at that dimmer level was.
  json how;
  json log = api.get("/v1/events?topic=execution&limit=300");
  for (const auto& ev : log["items"]) {
    if (ev["payload"].contains("resumed_after_suspension")) how = ev["payload"]["resumed_after_suspension"];
  }
  ASSERT_TRUE(how.is_object()) << log.dump();
  EXPECT_EQ(how["cause"], "lamp:drift");
  EXPECT_EQ(how["lamps"], json::array({"D65"}));
  ASSERT_TRUE(how.contains("change_pct")) << how.dump();
  EXPECT_NEAR(how["change_pct"].get<double>(),
              (how["stable_level"].get<double>() / how["level_before"].get<double>() - 1) * 100, 1e-9);

  // The drift is over (back to normal) and D65 warm: the truth of an undisturbed run at each spot and level.
  json truth = control(daemon, {{"cmd", "truth"}});
  EXPECT_DOUBLE_EQ(truth["drift"]["D65"]["factor"].get<double>(), 1.0) << truth["drift"].dump();
  EXPECT_EQ(truth["drift"]["D65"]["start_s"], drift["lamp_drift"]["start_s"]);
  json run = colorlab::client::fetch_run(api, e["run_id"].get<std::string>());
  // Every step once, in the grid's order (spot-major; the lamp stays lit, so from the second spot on its
  // levels run the other way round).
  std::vector<std::string> expected_steps{"L/D65/D100/r0c0", "L/D65/D50/r0c0"};
  for (int c = 1; c < 4; ++c) {
    expected_steps.push_back("L/D65/D50/r0c" + std::to_string(c));
    expected_steps.push_back("L/D65/D100/r0c" + std::to_string(c));
  }
  std::vector<std::string> steps;
  for (const auto& m : run["measurements"]) steps.push_back(m["step"]);
  EXPECT_EQ(steps, expected_steps);
  // Every reading within 4 σ of the LS-110's noise at the spot's truth, plus the 1 % a lamp may still be
  // below full output when the stability criterion accepts it: none taken while the light was away.
  for (const auto& m : run["measurements"]) {
    const auto& d = m["data"];
    control(daemon, {{"cmd", "aim"}, {"row", d["row"]}, {"col", d["col"]}});
    control(daemon, {{"cmd", "dimmer"}, {"percent", d["dimmer_percent"]}});
    json t = control(daemon, {{"cmd", "truth"}})["ls110"];
    const double l = t["luminance"].get<double>(), sigma = t["noise_sigma"].get<double>();
    EXPECT_NEAR(m["value"].get<double>(), l, 4 * sigma + 0.01 * l) << m["step"];
  }
  // The grid lists the spot it read again, so its maps do not mix light levels silently.
  const auto& changes = run["summary"]["script"]["light_changes"];
  ASSERT_EQ(changes.size(), 1u) << changes.dump();
  EXPECT_EQ(changes[0]["cause"], "lamp:drift");
  EXPECT_EQ(changes[0]["col"], 1);
  daemon.kill9();
}

}  // namespace
