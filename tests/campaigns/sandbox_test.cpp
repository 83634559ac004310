// A campaign script cannot escape its sandbox or hold the daemon: forbidden libraries, bytecode,
// endless loops (even under pcall), unbounded allocation and plain runtime errors each end the
// run with a typed script_error naming the script, the line and the step.
#include <chrono>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/detached.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/use_future.hpp>
#include <gtest/gtest.h>

#include "engine_harness.hpp"

using colorlab::ErrorClass;
using colorlab::campaigns::ExecutionControl;
using colorlab::campaigns::RunOutcome;
using colorlab::campaigns::ScriptRunSetup;
using colorlab::testing::MemorySink;
using colorlab::testing::run_script;
using colorlab::testing::script_from;

namespace {

RunOutcome run_body(const std::string& body, const std::string& limits = "") {
  std::string source = "return {\n" + limits + "run = function(p)\n" + body + "\nend }\n";
  ScriptRunSetup setup;
  setup.script = script_from("probe", source);
  MemorySink sink;
  ExecutionControl control;
  return run_script(setup, sink, control).outcome;
}

void expect_script_error(const RunOutcome& o, const std::string& words, int line) {
  ASSERT_EQ(o.kind, RunOutcome::Kind::failed);
  ASSERT_TRUE(o.error);
  EXPECT_EQ(o.error->cls(), ErrorClass::script_error) << o.error->what();
  EXPECT_NE(std::string(o.error->what()).find(words), std::string::npos) << o.error->what();
  EXPECT_EQ(o.script_location["script"], "probe.lua");
  if (line > 0) {
    EXPECT_EQ(o.script_location["line"], line) << o.error->what();
  }
  EXPECT_TRUE(o.script_location.contains("step"));
}

}  // namespace

// The body starts on line 3 of the generated script.
TEST(Sandbox, ForbiddenLibrariesSayWhatIsForbidden) {
  expect_script_error(run_body("io.open('/etc/passwd')"), "io.open is forbidden", 3);
  expect_script_error(run_body("lab.progress(0, 'x')\nos.execute('true')"), "os.execute is forbidden", 4);
  expect_script_error(run_body("require('socket')"), "require is forbidden", 3);
  expect_script_error(run_body("dofile('/tmp/x.lua')"), "dofile is forbidden", 3);
  expect_script_error(run_body("local f = string.dump(print)"), "string.dump is forbidden", 3);
  expect_script_error(run_body("load('\\27Lua')"), "bytecode is forbidden", 3);
  expect_script_error(run_body("debug.sethook()"), "debug.sethook is forbidden", 3);
  expect_script_error(run_body("collectgarbage('stop')"), "collectgarbage is forbidden", 3);
}

TEST(Sandbox, TextLoadStaysInTheSandbox) {
  auto o = run_body("local f = load('return io')\nlocal io2 = f()\nio2.open('x')");
  expect_script_error(o, "io.open is forbidden", 5);
}

TEST(Sandbox, RuntimeErrorNamesLineAndStep) {
  auto o = run_body("lab.progress(0.5, 'spot/r3c4')\nlocal t = nil\nreturn t.x");
  expect_script_error(o, "attempt to index", 5);
  EXPECT_EQ(o.script_location["step"], "spot/r3c4");
  EXPECT_NE(std::string(o.error->what()).find("step spot/r3c4"), std::string::npos);
}

TEST(Sandbox, EndlessLoopEndsOnTheBudgetEvenUnderPcall) {
  const std::string limits = "limits = { instruction_budget = 20000000 },\n";
  expect_script_error(run_body("while true do end", limits), "instruction budget", 4);  // the limits line moves it
  // The script's own pcall cannot swallow the budget error: every further instruction raises.
  auto o = run_body("while true do pcall(function() while true do end end) end", limits);
  expect_script_error(o, "instruction budget", 0);
  // A lab call resets the budget: a long campaign with short work between calls is fine.
  auto ok = run_body("for i = 1, 30 do local x = 0 for j = 1, 100000 do x = x + j end lab.checkpoint() end", limits);
  EXPECT_EQ(ok.kind, RunOutcome::Kind::finished) << (ok.error ? ok.error->what() : "");
}

TEST(Sandbox, UnboundedAllocationEndsOnTheMemoryLimit) {
  const std::string limits = "limits = { memory_mib = 8 },\n";
  expect_script_error(run_body("local t = {}\nwhile true do t[#t + 1] = string.rep('x', 4096) .. #t end", limits),
                      "memory limit of 8 MiB", 0);
  // Caught by pcall, it still ends the script.
  auto o = run_body("while true do pcall(function() local t = {} while true do t[#t+1] = {} end end) end", limits);
  expect_script_error(o, "memory limit", 0);
}

TEST(Sandbox, ScriptCannotYieldTheEngineFromItsOwnCoroutine) {
  auto o = run_body("local co = coroutine.create(function() lab.wait(1) end)\nlocal ok, err = coroutine.resume(co)\nerror(err)");
  expect_script_error(o, "cannot be called from a coroutine", 0);
}

TEST(Sandbox, BadLabArgumentsAreScriptErrorsAtTheCallingLine) {
  expect_script_error(run_body("lab.wait('soon')"), "bad argument #1 to lab.wait", 3);
  expect_script_error(run_body("lab.dimmer.set(150)"), "from 0 to 100", 3);
  expect_script_error(run_body("lab.record('a', {value = 1})"), "quantity", 3);
  expect_script_error(run_body("lab.record('a', {quantity = 'q'})\nlab.record('a', {quantity = 'q'})"), "recorded twice", 4);
}

// A long computation between lab calls yields to the event loop every slice: a timer (the
// systemd watchdog's, in colorlabd) keeps firing while the script computes.
TEST(Sandbox, LongComputationDoesNotStarveTheEventLoop) {
  boost::asio::io_context io;
  colorlab::campaigns::InstrumentSet none;
  colorlab::campaigns::Lab lab(io.get_executor(), none, {});
  ScriptRunSetup setup;
  setup.script = script_from("compute", R"lua(return { limits = { instruction_budget = 1e9 }, run = function()
    local x = 0
    for i = 1, 60000000 do x = x + i % 7 end
    return { x = x }
  end })lua");
  MemorySink sink;
  ExecutionControl control;
  int ticks = 0;
  bool done = false;
  boost::asio::steady_timer timer(io);
  std::function<void()> arm = [&] {
    timer.expires_after(std::chrono::milliseconds(20));
    timer.async_wait([&](boost::system::error_code ec) {
      if (ec || done) return;
      ++ticks;
      arm();
    });
  };
  arm();
  auto start = std::chrono::steady_clock::now();
  auto future = boost::asio::co_spawn(
      io,
      [&]() -> boost::asio::awaitable<RunOutcome> {
        auto o = co_await colorlab::campaigns::run_campaign_script(setup, lab, sink, control);
        done = true;
        timer.cancel();
        co_return o;
      },
      boost::asio::use_future);
  io.run();
  auto o = future.get();
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(o.kind, RunOutcome::Kind::finished) << (o.error ? o.error->what() : "");
  // The timer fired throughout: at least a third of the 20 ms slots the computation took.
  EXPECT_GE(ticks, static_cast<int>(seconds / 0.020 / 3)) << "computation took " << seconds << " s";
  EXPECT_GE(ticks, 3);
}

// The analysis library from a script: §6.2 on a grid whose answer is known. A 4 × 5 block of
// equal values in an otherwise graded 8 × 10 half-grid is the only zero-spread window.
TEST(LabAnalysis, UniformityAndDimmerProportionalityFromAScript) {
  ScriptRunSetup setup;
  setup.script = script_from("grid", R"lua(return { run = function()
    local g = {}
    for r = 1, 8 do
      g[r] = {}
      for c = 1, 10 do g[r][c] = 100 + 3 * r + 7 * c end
    end
    for r = 3, 6 do for c = 2, 6 do g[r][c] = 150 end end
    local u = lab.analysis.uniformity(g)
    local half = {}
    for r = 1, #u.difference do
      half[r] = {}
      for c = 1, #u.difference[r] do half[r][c] = u.difference[r][c] * 0.5 end
    end
    local d = lab.analysis.dimmer_proportionality(u.difference, half, 0.5)
    local ok, err = pcall(lab.analysis.uniformity, { { 1, 2 }, { 3 } })
    return { best = u.best, min = u.min, max = u.max, dimmer_error = d.max_abs_error, ragged = err }
  end })lua");
  MemorySink sink;
  ExecutionControl control;
  auto o = run_script(setup, sink, control).outcome;
  ASSERT_EQ(o.kind, RunOutcome::Kind::finished) << (o.error ? o.error->what() : "");
  EXPECT_EQ(o.result["best"]["row"], 2);  // 0-based: rows 3..6, columns 2..6 in Lua's 1-based terms
  EXPECT_EQ(o.result["best"]["col"], 1);
  EXPECT_NEAR(o.result["best"]["stdev"].get<double>(), 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(o.result["min"].get<double>(), 110.0);
  EXPECT_NEAR(o.result["dimmer_error"].get<double>(), 0.0, 1e-9);  // exactly proportional by construction
  EXPECT_NE(o.result["ragged"].get<std::string>().find("every row needs 2 values"), std::string::npos);
}

// A script that knows what a person must do raises error{message, hint, class}: the run fails with that hint and a
// class for people (characterize-camera's refused photograph), never one the engine acts on (io_error suspends).
TEST(Sandbox, AnErrorTableCarriesItsHintAndAClassForPeople) {
  auto o = run_body("error({ message = 'the chart was not located', hint = 'give corners_raw', class = 'needs_operator' })");
  ASSERT_EQ(o.kind, RunOutcome::Kind::failed);
  ASSERT_TRUE(o.error);
  EXPECT_EQ(o.error->cls(), ErrorClass::needs_operator);
  EXPECT_NE(std::string(o.error->what()).find("the chart was not located"), std::string::npos) << o.error->what();
  EXPECT_EQ(o.error->hint(), "give corners_raw");
  auto suspending = run_body("error({ message = 'disk', class = 'io_error' })");
  ASSERT_EQ(suspending.kind, RunOutcome::Kind::failed);
  EXPECT_EQ(suspending.error->cls(), ErrorClass::script_error);
  EXPECT_EQ(suspending.error->hint(), "fix the script and start a new run");
  auto plain = run_body("error('plain')");
  EXPECT_EQ(plain.error->hint(), "fix the script and start a new run");
}
