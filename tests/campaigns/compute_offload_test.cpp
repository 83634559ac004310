// lab.analysis.characterize through ScriptRunSetup::compute (issue 27): the engine hands the fit to
// whoever computes (the daemon's worker pool) and resumes the script with its result; the job's
// error becomes the script's error at the calling line; without a compute hook the fit runs inline.
#include <gtest/gtest.h>

#include <boost/asio/awaitable.hpp>

#include "engine_harness.hpp"

using colorlab::campaigns::ExecutionControl;
using colorlab::campaigns::RunOutcome;
using colorlab::campaigns::ScriptRunSetup;
using colorlab::testing::MemorySink;
using colorlab::testing::run_script;
using colorlab::testing::script_from;
using nlohmann::json;

namespace {

const char* kFit = R"lua(
return {
  run = function(p)
    local t = lab.now()
    local r = lab.analysis.characterize({ ids = { "A" }, values = { { 1, 2, 3 } } }, { ids = { "A" } }, {})
    lab.record("fit", { quantity = "best", data = r })
    return { got = r.fake, after = lab.now().unix >= t.unix }
  end,
}
)lua";

ScriptRunSetup setup_with(std::function<boost::asio::awaitable<json>(std::string, std::function<json()>)> compute) {
  ScriptRunSetup s;
  s.script = script_from("fit", kFit);
  s.params = s.script->validate(json::object());
  s.random_seed = 1;
  s.compute = std::move(compute);
  return s;
}

}  // namespace

TEST(ComputeOffload, TheScriptGetsWhatTheComputeHookReturns) {
  std::vector<std::string> asked;
  MemorySink sink;
  ExecutionControl control;
  auto run = run_script(setup_with([&](std::string what, std::function<json()>) -> boost::asio::awaitable<json> {
                          asked.push_back(what);
                          co_return json{{"fake", 42}};
                        }),
                        sink, control);
  ASSERT_EQ(run.outcome.kind, RunOutcome::Kind::finished) << (run.outcome.error ? run.outcome.error->what() : "");
  EXPECT_EQ(run.outcome.result["got"], 42);
  EXPECT_EQ(run.outcome.result["after"], true);
  EXPECT_EQ(asked, std::vector<std::string>{"lab.analysis.characterize"});
  // A computation is no lab call: the journal has only the two lab.now calls.
  ASSERT_EQ(sink.journal().size(), 2u);
  EXPECT_EQ(sink.journal()[0].call, "now");
  EXPECT_EQ(sink.journal()[1].call, "now");
}

TEST(ComputeOffload, TheJobsErrorIsTheScriptsErrorAtTheCallingLine) {
  int ran = 0;
  MemorySink sink;
  ExecutionControl control;
  auto run = run_script(setup_with([&](std::string, std::function<json()> job) -> boost::asio::awaitable<json> {
                          ++ran;
                          co_return job();  // one patch: characterize refuses it
                        }),
                        sink, control);
  EXPECT_EQ(ran, 1);
  ASSERT_EQ(run.outcome.kind, RunOutcome::Kind::failed);
  ASSERT_TRUE(run.outcome.error);
  EXPECT_NE(std::string(run.outcome.error->what()).find("lab.analysis.characterize"), std::string::npos)
      << run.outcome.error->what();
  EXPECT_EQ(run.outcome.script_location["line"], 5) << run.outcome.script_location.dump();
}

TEST(ComputeOffload, WithoutAHookTheFitRunsInlineWithTheSameError) {
  MemorySink sink;
  ExecutionControl control;
  auto run = run_script(setup_with(nullptr), sink, control);
  ASSERT_EQ(run.outcome.kind, RunOutcome::Kind::failed);
  EXPECT_NE(std::string(run.outcome.error->what()).find("lab.analysis.characterize"), std::string::npos)
      << run.outcome.error->what();
  EXPECT_EQ(run.outcome.script_location["line"], 5) << run.outcome.script_location.dump();
}
