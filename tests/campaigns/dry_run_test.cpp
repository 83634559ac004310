// The dry run's parts that need no instruments: the timing keys the engine learns under and the dry
// run estimates with, the engine recording them for live calls only, and the dry run's arithmetic,
// operator actions and script errors on a lab with nothing in it.
#include <gtest/gtest.h>

#include "colorlab/campaigns/call_timing.hpp"
#include "colorlab/campaigns/dry_run.hpp"
#include "engine_harness.hpp"

using namespace colorlab::campaigns;
using colorlab::testing::MemorySink;
using colorlab::testing::run_script;
using colorlab::testing::script_from;
using nlohmann::json;

TEST(TimingKeys, ALampIsColdFromBeingLitUntilAStableWaitAndForgetsItsWarmthWhenSwitchedOff) {
  TimingKeys k;
  EXPECT_EQ(k.key("wait_stable", json::array()), "wait_stable warm");  // nothing lit, nothing to warm
  k.follow("lamps.select", {"D65"}, {{"lamps_on", {"D65"}}});
  EXPECT_EQ(k.key("wait_stable", json::array()), "wait_stable cold D65");
  k.follow("wait_stable", json::array(), json::object());
  EXPECT_EQ(k.key("wait_stable", json::array()), "wait_stable warm");
  // D65 stays lit and warm; TL84 is new.
  k.follow("lamps.set", {{"D65", "TL84"}}, {{"lamps_on", {"D65", "TL84"}}});
  EXPECT_EQ(k.key("wait_stable", json::array()), "wait_stable cold TL84");
  k.follow("wait_stable", json::array(), json::object());
  k.follow("lamps.off", json::array(), {{"lamps_on", json::array()}});
  k.follow("lamps.select", {"D65"}, {{"lamps_on", {"D65"}}});
  EXPECT_EQ(k.key("wait_stable", json::array()), "wait_stable cold D65");
}

TEST(TimingKeys, PhotographsCountPerFrameAndFormatAndTheScriptsOwnWaitsAreExact) {
  EXPECT_EQ(TimingKeys::units("camera.photograph_chart", {{{"frames", 25}, {"formats", {"raw", "jpeg"}}}}), 50.0);
  EXPECT_EQ(TimingKeys::units("camera.photograph_chart", {{{"frames", 3}}}), 12.0);  // four formats by default
  EXPECT_EQ(TimingKeys::units("camera.capture", {{{"frames", 7}}}), 7.0);
  EXPECT_EQ(TimingKeys::units("meter.measure", json::array()), 1.0);
  EXPECT_EQ(TimingKeys::asked_wait_s("dimmer.set", {50, {{"settle_s", 12}}}), 12.0);
  EXPECT_EQ(TimingKeys::asked_wait_s("wait", {30}), 30.0);
  TimingKeys k;
  EXPECT_EQ(k.key("operator.request", {{{"action", "aim_meter"}, {"prompt", "aim"}}}), "operator.request aim_meter");
}

namespace {

const char* kWaiting = R"lua(
return {
  parameters = { n = { type = "integer", default = 3 } },
  run = function(p)
    for i = 1, p.n do
      lab.wait(2)
      lab.record("t/" .. i, { quantity = "time", value = lab.now().unix })
    end
    return {}
  end,
}
)lua";

}  // namespace

TEST(EngineTimings, LiveCallsAreTimedInLabSecondsWithoutTheirAskedWaitAndReplayedOnesAreNot) {
  auto script = script_from("waiting", kWaiting);
  ScriptRunSetup setup;
  setup.script = script;
  setup.params = script->validate(json::object());
  MemorySink sink;
  ExecutionControl control;
  auto run = run_script(setup, sink, control, 10);
  ASSERT_EQ(run.outcome.kind, RunOutcome::Kind::finished);
  std::map<std::string, int> timed;
  for (const auto& c : sink.commits) {
    for (const auto& t : c.timings) {
      ++timed[t.key];
      EXPECT_GE(t.lab_seconds, 0.0);
      // lab.wait(2) takes 2 lab seconds (0.2 s here), not counted; what is left is the engine's own
      // time × 10 — a commit to memory and a timer, far below the 2 s the script asked for.
      if (t.key == "wait") EXPECT_LT(t.lab_seconds, 1.0);
    }
  }
  EXPECT_EQ(timed["wait"], 3);
  EXPECT_EQ(timed["now"], 3);

  // Resumed from everything committed: nothing is timed again.
  ScriptRunSetup again = setup;
  again.journal = sink.journal();
  again.stored_steps = sink.steps();
  MemorySink resumed;
  auto second = run_script(again, resumed, control, 10);
  ASSERT_EQ(second.outcome.kind, RunOutcome::Kind::finished);
  for (const auto& c : resumed.commits) EXPECT_TRUE(c.timings.empty());
}

namespace {

const char* kNight = R"lua(
return {
  needs = { "luminance_meter" },
  parameters = { spots = { type = "integer", default = 4 } },
  run = function(p)
    for i = 1, p.spots do
      local a = lab.operator.request { action = "aim_meter", prompt = "aim at " .. i, options = { "aimed", "skip" },
                                       default = "skip", timeout_s = 600 }
      if a.answer == "aimed" then lab.record("spot/" .. i, { quantity = "x", value = i }) end
      lab.wait(10)
    end
    if p.spots > 5 then error("too many spots") end
    return {}
  end,
}
)lua";

}  // namespace

TEST(DryRunCampaign, AddsTheScriptsWaitsAndTheLabsTimingsAndListsWhatItCannotDo) {
  auto script = script_from("night", kNight);
  DryRunSetup setup;
  setup.script = script;
  setup.params = script->validate(json::object());
  setup.options.time_scale = 10;
  json r = dry_run_campaign(setup);
  // No meter in an empty lab; no hands: each aim waits for a person, at most its timeout.
  EXPECT_FALSE(r["ok"].get<bool>());
  EXPECT_TRUE(r["finished"].get<bool>());
  ASSERT_EQ(r["problems"].size(), 1u) << r.dump(2);
  EXPECT_EQ(r["problems"][0]["kind"], "instrument");
  EXPECT_EQ(r["operator_actions"][0]["count"], 4);
  EXPECT_EQ(r["operator_actions"][0]["by"], "operator");
  EXPECT_EQ(r["measurements"], 4);  // the action done: the first option
  const json& e = r["estimate"];
  EXPECT_NEAR(e["operator_wait_s"].get<double>(), 4 * 600.0, 1e-9);
  EXPECT_NEAR(e["lab_seconds"].get<double>(), 4 * 600.0 + 4 * 10.0, 1.0);
  EXPECT_NEAR(e["wall_seconds"].get<double>(), (4 * 600.0 + 4 * 10.0) / 10, 0.1);
  EXPECT_NEAR(e["measured_share"].get<double>(), 40.0 / 2440.0, 1e-12);  // only lab.wait's own time is exact

  // A script error stops the dry run at its line, as it would stop the run.
  setup.params = script->validate(json{{"spots", 6}});
  json failed = dry_run_campaign(setup);
  EXPECT_FALSE(failed["finished"].get<bool>());
  EXPECT_EQ(failed["stopped_at"]["line"], 12);
}
