// What the lab's hands moved for a run is put back when the run ends, in any state (issue 23's loose end: an
// aborted lens calibration left the simulated chart posed, and the next characterize-camera photographed it there).
// The hands here are a model of a chart stand: a pose is wherever the last place_chart put it, its rest the
// measuring place. Truth: after the run the stand is at rest, whatever ended it — the script's own last step
// ("put the chart back") reached or not — and a run that put it back itself is not moved again.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "colorlab/core/error.hpp"
#include "engine_harness.hpp"

namespace colorlab::campaigns {
namespace {

using nlohmann::json;
using testing::MemorySink;
using testing::run_script;
using testing::script_from;

class ChartStand final : public OperatorHands {
 public:
  bool can_perform(const std::string& action) const override { return action == "place_chart"; }
  boost::asio::awaitable<std::optional<json>> perform(const std::string& action, const json& details) override {
    if (action != "place_chart") co_return std::nullopt;
    ++moves;
    at = details.value("pose", json()) == "measurement" ? json("rest") : details;
    co_return json{{"placed", at}};
  }
  boost::asio::awaitable<std::optional<json>> put_back(const std::string& action, const json& details) override {
    asked.push_back(action + " " + details.dump());
    if (refuse) throw Error(ErrorClass::no_comms, "the stand does not answer");
    if (action != "place_chart" || details.value("pose", json()) == "measurement") co_return std::nullopt;
    ++moves;
    at = "rest";
    co_return json{{"placed", "rest"}};
  }
  json at = "rest";
  int moves = 0;
  bool refuse = false;
  std::vector<std::string> asked;
};

// Two poses; then, by `ending`: the script fails, finishes without putting the chart back, or puts it back itself.
// lab.wait is the safe point an abort, a pause or a shutdown lands on after the second pose.
const char* kScript = R"lua(
return {
  parameters = { ending = { type = "string", default = "back" } },
  run = function(p)
    for k = 1, 2 do
      lab.operator.request { action = "place_chart", prompt = "pose " .. k, options = { "placed", "skip" },
                             details = { pose = k, tilt_deg = 20 * k } }
      lab.record("pose/" .. k, { quantity = "pose", value = k })
    end
    if p.ending == "fail" then error({ class = "needs_operator", message = "only 2 poses" }) end
    lab.wait(0.01)
    if p.ending == "back" then
      lab.operator.request { action = "place_chart", prompt = "back", options = { "placed", "skip" }, details = { pose = "measurement" } }
    end
    return { ending = p.ending }
  end,
}
)lua";

ScriptRunSetup setup(const std::string& ending) {
  ScriptRunSetup s;
  s.script = script_from("poses", kScript);
  s.params = s.script->validate(json{{"ending", ending}});
  s.random_seed = 1;
  return s;
}

TEST(PutBack, WhatTheHandsMovedIsAtRestHoweverTheRunEnds) {
  struct Case {
    const char* ending;
    ExecutionControl::Request request;
    RunOutcome::Kind kind;
  };
  const Case cases[] = {
      {"back", ExecutionControl::Request::none, RunOutcome::Kind::finished},
      {"stay", ExecutionControl::Request::none, RunOutcome::Kind::finished},
      {"fail", ExecutionControl::Request::none, RunOutcome::Kind::failed},
      {"back", ExecutionControl::Request::abort, RunOutcome::Kind::aborted},
      {"back", ExecutionControl::Request::pause, RunOutcome::Kind::paused},
      {"back", ExecutionControl::Request::shutdown, RunOutcome::Kind::suspended},
  };
  for (const auto& c : cases) {
    const std::string what = std::string(c.ending) + " / outcome " + std::to_string(static_cast<int>(c.kind));
    ChartStand stand;
    MemorySink sink;
    ExecutionControl control;
    // The first commit is the step before the second pose: the request lands at the safe point after it.
    sink.on_commit = [&](std::size_t n) {
      if (n == 1 && c.request != ExecutionControl::Request::none) control.request = c.request, control.reason = "test";
    };
    const auto r = run_script(setup(c.ending), sink, control, 1000, &stand);
    EXPECT_EQ(r.outcome.kind, c.kind) << what << ": " << (r.outcome.error ? r.outcome.error->what() : "");
    EXPECT_EQ(stand.at, "rest") << what;
    if (c.request != ExecutionControl::Request::none || std::string(c.ending) != "back") {
      // Stopped or ended with the chart at pose 2: put back from there, once.
      ASSERT_EQ(stand.asked.size(), 1u) << what;
      EXPECT_NE(stand.asked[0].find("\"pose\":2"), std::string::npos) << stand.asked[0];
      EXPECT_EQ(stand.moves, 3) << what;
    } else {
      EXPECT_EQ(stand.moves, 3) << what << ": the script put it back; nothing more moves";
    }
  }
}

TEST(PutBack, AHandThatCannotPutBackLeavesTheRunsOwnOutcome) {
  ChartStand stand;
  stand.refuse = true;
  MemorySink sink;
  ExecutionControl control;
  const auto r = run_script(setup("fail"), sink, control, 1000, &stand);
  ASSERT_EQ(r.outcome.kind, RunOutcome::Kind::failed);
  ASSERT_TRUE(r.outcome.error);
  EXPECT_EQ(r.outcome.error->cls(), ErrorClass::needs_operator);
  EXPECT_NE(std::string(r.outcome.error->what()).find("only 2 poses"), std::string::npos) << r.outcome.error->what();
  EXPECT_EQ(stand.asked.size(), 1u);
}

// A failure that is not colorlab's own (a library's exception out of a commit) is the execution's to record, but
// the stand is put back before it leaves the engine; a deliberate crash (the harness's CrashNow) is not.
TEST(PutBack, AForeignExceptionStillPutsBackAndLeavesTheEngine) {
  ChartStand stand;
  MemorySink sink;
  ExecutionControl control;
  sink.on_commit = [&](std::size_t n) {
    if (n == 1) throw std::runtime_error("a library's own exception");
  };
  EXPECT_THROW(run_script(setup("back"), sink, control, 1000, &stand), std::runtime_error);
  EXPECT_EQ(stand.at, "rest");
  ASSERT_EQ(stand.asked.size(), 1u);
  EXPECT_NE(stand.asked[0].find("\"pose\":1"), std::string::npos) << stand.asked[0];
}

}  // namespace
}  // namespace colorlab::campaigns
