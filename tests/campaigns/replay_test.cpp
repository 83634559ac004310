// Deterministic replay, exhaustively: a script that draws random numbers, asks the time, iterates
// tables with string keys and records as it goes is "killed" after every possible commit, then
// resumed from what was committed. Each resumed run must store exactly the steps, and the values,
// of the uninterrupted run: nothing lost, nothing repeated, nothing different.
#include <map>

#include <gtest/gtest.h>

#include "engine_harness.hpp"

using colorlab::campaigns::ExecutionControl;
using colorlab::campaigns::RecordedMeasurement;
using colorlab::campaigns::RunOutcome;
using colorlab::campaigns::ScriptRunSetup;
using colorlab::testing::MemorySink;
using colorlab::testing::run_script;
using colorlab::testing::script_from;

namespace {

const char* kScript = R"lua(
return {
  parameters = { n = { type = "integer", default = 6 } },
  run = function(p)
    local seen = {}
    local weights = { alpha = 1, beta = 2, gamma = 3, delta = 4, epsilon = 5 }
    for i = 1, p.n do
      local step = "step/" .. i
      lab.progress(i / p.n, step)
      local t = lab.now()
      local order = {}
      for k, v in pairs(weights) do order[#order + 1] = k .. "=" .. v end
      local r = math.random()
      lab.record(step, { quantity = "draw", value = r, data = { order = table.concat(order, ","), t = t.unix } })
      seen[#seen + 1] = r
      if i % 2 == 0 then lab.wait(0.5) end
    end
    return { count = #seen, last = seen[#seen] }
  end,
}
)lua";

std::map<std::string, RecordedMeasurement> by_step(const std::vector<RecordedMeasurement>& ms) {
  std::map<std::string, RecordedMeasurement> out;
  for (const auto& m : ms) {
    EXPECT_TRUE(out.emplace(m.step, m).second) << m.step << " stored twice";
  }
  return out;
}

ScriptRunSetup fresh_setup() {
  ScriptRunSetup s;
  s.script = script_from("replay", kScript);
  s.params = s.script->validate(nlohmann::json::object());
  s.random_seed = 12345;
  return s;
}

}  // namespace

TEST(Replay, KilledAfterAnyCommitTheResumedRunEqualsTheUninterruptedOne) {
  MemorySink reference;
  ExecutionControl control;
  auto ref = run_script(fresh_setup(), reference, control);
  ASSERT_EQ(ref.outcome.kind, RunOutcome::Kind::finished);
  auto expected = by_step(reference.measurements());
  ASSERT_EQ(expected.size(), 6u);
  const std::size_t commits = reference.commits.size();
  ASSERT_GE(commits, 6u);

  for (std::size_t kill_after = 0; kill_after < commits; ++kill_after) {
    SCOPED_TRACE("killed after commit " + std::to_string(kill_after));
    MemorySink first;
    first.crash_after = kill_after;
    ExecutionControl c1;
    ASSERT_TRUE(run_script(fresh_setup(), first, c1).crashed);

    // What a restarted daemon reads back from the store.
    ScriptRunSetup resume = fresh_setup();
    resume.journal = first.journal();
    resume.stored_steps = first.steps();
    MemorySink second;
    ExecutionControl c2;
    auto resumed = run_script(resume, second, c2);
    ASSERT_EQ(resumed.outcome.kind, RunOutcome::Kind::finished) << (resumed.outcome.error ? resumed.outcome.error->what() : "");
    EXPECT_EQ(resumed.outcome.replayed, static_cast<std::int64_t>(resume.journal.size()));
    EXPECT_EQ(resumed.outcome.result, ref.outcome.result);

    auto all = first.measurements();
    auto more = second.measurements();
    all.insert(all.end(), more.begin(), more.end());
    auto got = by_step(all);
    ASSERT_EQ(got.size(), expected.size());
    for (const auto& [step, m] : expected) {
      ASSERT_TRUE(got.count(step)) << step << " lost";
      EXPECT_EQ(got[step].value, m.value) << step;
      EXPECT_EQ(got[step].data["order"], m.data["order"]) << step;
    }
    // Journal positions continue where the first process stopped: no gap, no overlap.
    auto journal = first.journal();
    for (const auto& j : second.journal()) journal.push_back(j);
    for (std::size_t i = 0; i < journal.size(); ++i) EXPECT_EQ(journal[i].seq, static_cast<std::int64_t>(i));
  }
}

TEST(Replay, AnEditedScriptThatNoLongerReplaysIsRefusedNotMixed) {
  MemorySink first;
  first.crash_after = 8;
  ExecutionControl c1;
  ASSERT_TRUE(run_script(fresh_setup(), first, c1).crashed);
  bool waited = false;
  for (const auto& j : first.journal()) waited = waited || j.call == "wait";
  ASSERT_TRUE(waited) << "the journal must reach the edited call";
  ScriptRunSetup resume = fresh_setup();
  resume.script = script_from("replay", std::string(kScript).replace(std::string(kScript).find("lab.wait(0.5)"), 13, "lab.wait(0.7)"));
  resume.journal = first.journal();
  resume.stored_steps = first.steps();
  MemorySink second;
  ExecutionControl c2;
  auto r = run_script(resume, second, c2);
  ASSERT_EQ(r.outcome.kind, RunOutcome::Kind::failed);
  EXPECT_NE(std::string(r.outcome.error->what()).find("replay diverged"), std::string::npos) << r.outcome.error->what();
}

TEST(Replay, PauseAndAbortLandAtASafePointWithTheStepCommitted) {
  for (auto request : {ExecutionControl::Request::pause, ExecutionControl::Request::abort, ExecutionControl::Request::shutdown}) {
    MemorySink sink;
    ExecutionControl control;
    sink.on_commit = [&](std::size_t n) {
      if (n == 3) {
        control.request = request;
        control.reason = "test";
      }
    };
    auto r = run_script(fresh_setup(), sink, control);
    auto kind = request == ExecutionControl::Request::pause   ? RunOutcome::Kind::paused
                : request == ExecutionControl::Request::abort ? RunOutcome::Kind::aborted
                                                              : RunOutcome::Kind::suspended;
    EXPECT_EQ(r.outcome.kind, kind);
    EXPECT_EQ(r.outcome.reason, "test");
    // Whatever was measured before the safe point is committed; the rest is not taken.
    auto steps = sink.steps();
    EXPECT_GE(steps.size(), 1u);
    EXPECT_LT(steps.size(), 6u);
  }
}
