// The campaign engine inside colorlabd, as a lab uses it: scripts dropped into the campaigns
// directory, scripts that misbehave, pause/resume/abort from the API, SIGTERM in the middle of a
// run, and a step that kills the daemon every time (a bounded number of resumes, then a reason).
#include <stdlib.h>
#include <csignal>
#include <cstring>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>

#include "colorlab/client/api_client.hpp"
#include "colorlab/client/runs.hpp"
#include "colorlab/testing/notify_socket.hpp"
#include "resume_support.hpp"

using namespace colorlab::testing;
using colorlab::client::ApiClient;
using nlohmann::json;

namespace {

json start(const ApiClient& api, const std::string& campaign, const json& params) {
  return api.post("/v1/executions", {{"campaign", campaign}, {"params", params}});
}

json wait_status(const ApiClient& api, const std::string& id, const std::string& status,
                 std::chrono::seconds timeout = std::chrono::seconds(30)) {
  auto deadline = std::chrono::steady_clock::now() + timeout;
  json e;
  while (std::chrono::steady_clock::now() < deadline) {
    e = api.get("/v1/executions/" + id);
    if (e["status"] == status) return e;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return e;
}

std::size_t measurement_count(const ApiClient& api, const json& execution) {
  return colorlab::client::fetch_run(api, execution["run_id"].get<std::string>())["measurements"].size();
}

void wait_measurements(const ApiClient& api, const json& execution, std::size_t n) {
  for (int i = 0; i < 600 && measurement_count(api, execution) < n; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
}

}  // namespace

TEST(EngineInDaemon, AScriptDroppedIntoTheCampaignsDirectoryAppearsAndRunsWithoutRestart) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 20, 1));
  auto api = api_for(daemon);
  auto names = [&] {
    std::set<std::string> out;
    json campaigns = api.get("/v1/campaigns");  // a temporary's member would dangle in the loop
    for (const auto& c : campaigns["items"]) out.insert(c["name"].get<std::string>());
    return out;
  };
  EXPECT_EQ(names().count("twice"), 0u);
  write_campaign(dir.path(), "twice.lua", R"lua(
return {
  description = "two readings, their difference",
  needs = { "luminance_meter" },
  parameters = { label = { type = "string", default = "spot", description = "a name" } },
  run = function(p)
    local a = lab.meter.measure()
    lab.record(p.label .. "/a", { quantity = "luminance", value = a.luminance, unit = a.unit, instrument = a.instrument })
    local b = lab.meter.measure()
    lab.record(p.label .. "/b", { quantity = "luminance", value = b.luminance, unit = b.unit, instrument = b.instrument })
    return { difference = b.luminance - a.luminance }
  end,
}
)lua");
  ASSERT_TRUE(std::filesystem::exists(dir / "state" / "campaigns" / "twice.lua"));
  auto listed = names();
  ASSERT_EQ(listed.count("twice"), 1u) << api.get("/v1/campaigns")["broken"].dump() << " " << listed.size();
  auto e = start(api, "twice", {{"label", "centre"}});
  auto done = wait_terminal(api, e["id"]);
  ASSERT_EQ(done["status"], "finished_ok") << done.dump();
  json run = colorlab::client::fetch_run(api, e["run_id"].get<std::string>());
  ASSERT_EQ(run["measurements"].size(), 2u);
  EXPECT_EQ(run["measurements"][0]["step"], "centre/a");
  EXPECT_EQ(run["measurements"][0]["instrument_id"], "ls110");
  EXPECT_NEAR(run["summary"]["script"]["difference"].get<double>(),
              run["measurements"][1]["value"].get<double>() - run["measurements"][0]["value"].get<double>(), 1e-9);
  // The run describes itself: the exact script text it ran, by hash.
  auto script = api.request("GET", "/v1/runs/" + e["run_id"].get<std::string>() + "/script");
  EXPECT_EQ(script.status, 200);
  EXPECT_NE(script.body.find("two readings, their difference"), std::string::npos);
  EXPECT_EQ(run["script"]["sha256"].get<std::string>().size(), 64u);
  // Parameters are validated before anything moves.
  try {
    start(api, "twice", {{"label", 3}});
    FAIL() << "a bad parameter was accepted";
  } catch (const colorlab::client::ApiError& err) {
    EXPECT_EQ(err.problem().status, 400);
    EXPECT_NE(err.problem().detail.find("params.label"), std::string::npos);
  }
}

// Each misbehaving script ends in a typed error naming it and the line; meanwhile the event loop
// goes on feeding systemd's watchdog and serving the API.
TEST(EngineInDaemon, MisbehavingScriptsEndInTypedErrorsWhileTheDaemonKeepsServing) {
  TempDir dir;
  NotifySocket systemd(dir / "notify.sock");
  struct Case {
    const char* name;
    const char* body;
    const char* words;
    int line;
  };
  const Case cases[] = {
      {"spin", "local n = 0\nwhile true do n = n + 1 end", "instruction budget", 5},
      {"hoard", "local t = {}\nwhile true do t[#t + 1] = string.rep('x', 65536) .. #t end", "memory limit", 0},
      {"escape", "lab.progress(0.1, 'before escaping')\nlocal f = io.open('/etc/shadow')", "io.open is forbidden", 5},
      {"fails", "lab.progress(0.2, 'spot/r1c2')\n\nerror('the tile is dirty')", "the tile is dirty", 6},
  };
  for (const auto& c : cases) {
    write_campaign(dir.path(), std::string(c.name) + ".lua",
                   "return {\n  limits = { memory_mib = 16 },\n  run = function(p)\n" + std::string(c.body) +
                       "\n  end,\n}\n");
  }
  ::setenv("NOTIFY_SOCKET", systemd.path().c_str(), 1);
  ::setenv("WATCHDOG_USEC", "400000", 1);
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 20, 1));
  ::unsetenv("NOTIFY_SOCKET");
  ::unsetenv("WATCHDOG_USEC");
  auto api = api_for(daemon);
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    auto started = std::chrono::steady_clock::now();
    auto e = start(api, c.name, json::object());
    int pings = 0;
    json done;
    for (;;) {
      if (systemd.receive(std::chrono::milliseconds(20)).find("WATCHDOG=1") != std::string::npos) ++pings;
      done = api.get("/v1/executions/" + e["id"].get<std::string>());  // the API answers meanwhile
      if (done["status"] != "running" && done["status"] != "waiting") break;
      ASSERT_LT(std::chrono::steady_clock::now() - started, std::chrono::seconds(60));
    }
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    ASSERT_EQ(done["status"], "finished_error") << done.dump();
    EXPECT_EQ(done["error"]["code"], "script_error");
    EXPECT_NE(done["error"]["detail"].get<std::string>().find(c.words), std::string::npos) << done["error"].dump();
    EXPECT_EQ(done["error"]["script"], std::string(c.name) + ".lua");
    if (c.line > 0) {
      EXPECT_EQ(done["error"]["line"], c.line) << done["error"].dump();
    }
    // WatchdogSec 0.4 s → a ping every 0.2 s; the loop must not have starved it.
    if (seconds > 1.0) {
      EXPECT_GE(pings, static_cast<int>(seconds / 0.2 / 2)) << seconds << " s";
    }
  }
  EXPECT_EQ(api.get("/v1")["server"], "colorlabd");
}

TEST(EngineInDaemon, PauseResumeAndAbortLandAtSafePoints) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 4, 1));
  auto api = api_for(daemon);
  auto e = start(api, "luminance-spot", {{"readings", 200}});
  std::string id = e["id"];
  wait_measurements(api, e, 2);
  api.post("/v1/executions/" + id + "/pause", json::object());
  auto paused = wait_status(api, id, "paused");
  ASSERT_EQ(paused["status"], "paused") << paused.dump();
  EXPECT_EQ(paused["reason"], "paused by a client");
  auto held = measurement_count(api, e);
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  EXPECT_EQ(measurement_count(api, e), held) << "a paused execution must not measure";
  // A paused execution stays paused across a restart, and resumes on request.
  daemon.kill9();
  daemon.start();
  api = api_for(daemon);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(api.get("/v1/executions/" + id)["status"], "paused");
  api.post("/v1/executions/" + id + "/resume", json::object());
  wait_measurements(api, e, held + 2);
  EXPECT_GE(measurement_count(api, e), held + 2);
  api.post("/v1/executions/" + id + "/abort", json::object());
  auto aborted = wait_terminal(api, id);
  EXPECT_EQ(aborted["status"], "aborted");
  EXPECT_EQ(aborted["reason"], "aborted by a client");
  json run = colorlab::client::fetch_run(api, e["run_id"].get<std::string>());
  EXPECT_EQ(run["status"], "aborted");
  EXPECT_LT(run["measurements"].size(), 200u);
  // Nothing to pause or abort any more: a conflict, as problem+json.
  try {
    api.post("/v1/executions/" + id + "/abort", json::object());
    FAIL();
  } catch (const colorlab::client::ApiError& err) {
    EXPECT_EQ(err.problem().status, 409);
  }
}

TEST(EngineInDaemon, SigtermSuspendsTheRunningStepAndTheNextStartResumesIt) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 4, 1));
  auto api = api_for(daemon);
  auto e = start(api, "luminance-spot", {{"readings", 20}, {"interval_s", 1}});
  std::string id = e["id"];
  wait_measurements(api, e, 3);
  EXPECT_EQ(daemon.terminate(), 0) << "colorlabd must stop cleanly on SIGTERM";
  daemon.start();
  api = api_for(daemon);
  bool suspended = false;
  json events = api.get("/v1/events?topic=execution&limit=300");
  for (const auto& ev : events["items"]) {
    if (ev["payload"].value("execution_id", "") == id && ev["payload"].value("status", "") == "suspended") suspended = true;
  }
  EXPECT_TRUE(suspended) << "SIGTERM must leave the execution suspended with its reason";
  auto done = wait_terminal(api, id);
  EXPECT_EQ(done["status"], "finished_ok") << done.dump();
  json run = colorlab::client::fetch_run(api, e["run_id"].get<std::string>());
  ASSERT_EQ(run["measurements"].size(), 20u);
  for (int i = 0; i < 20; ++i) EXPECT_EQ(run["measurements"][i]["step"], "reading/" + std::to_string(i));
}

// Without back-off retries (crash_loop_retries = 0) the crash-loop guard ends the run as soon as it trips;
// crash_loop_test.cpp has the suspension and back-off that the default retries give.
TEST(EngineInDaemon, AStepThatKillsTheDaemonEveryTimeEndsAfterTheBoundedAttempts) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 1, 1,
                                                          "[campaigns]\nmax_resume_attempts = 2\ncrash_loop_retries = 0\n"));
  auto api = api_for(daemon);
  auto e = start(api, "luminance-spot", {{"readings", 100}});
  std::string id = e["id"];
  wait_measurements(api, e, 2);
  daemon.kill9();
  // The step after it "crashes" the daemon each time: killed as soon as it serves again, before
  // a reading (0.45 s at this time scale) can be committed.
  for (int attempt = 1; attempt <= 2; ++attempt) {
    daemon.start();
    daemon.kill9();
  }
  daemon.start();
  api = api_for(daemon);
  auto done = wait_terminal(api, id, std::chrono::seconds(10));
  ASSERT_EQ(done["status"], "finished_error") << done.dump();
  EXPECT_NE(done["reason"].get<std::string>().find("3 times in a row"), std::string::npos) << done.dump();
  EXPECT_EQ(done["resume_attempts"], 3);
  EXPECT_EQ(done["error"]["code"], "crash-loop") << "colorlabd's own trouble, not an instrument error: " << done.dump();
  EXPECT_EQ(done["error"]["title"], "Crash loop");
  // What was measured before stays.
  EXPECT_GE(measurement_count(api, e), 2u);
}

// After a crash the unit on the port may not be the one the run started with (swapped, or another
// widget enumerated first): the resumed run pauses with the reason instead of measuring with it, and
// an operator's resume accepts the unit.
TEST(EngineInDaemon, AnotherUnitOnResumePausesForTheOperator) {
  TempDir dir;
  // A short stability window: the relit lamp's warm-up is part of the restore.
  auto config = write_daemon_config(dir.path(), 20, 1, "[campaigns]\nstable_window_s = 20\n");
  std::ofstream(dir / "lab.toml") << "[genicam]\nenabled = false\n[dmx]\nserial = 11111111\n";
  write_campaign(dir.path(), "lit.lua", R"lua(
return {
  needs = { "lamps", "luminance_meter" },
  run = function(p)
    lab.lamps.select("D65")
    lab.dimmer.set(100, { settle_s = 1 })  -- the widget sends the whole universe: an unset dimmer is 0 %
    lab.wait_stable({ window_s = 20 })     -- as any campaign does before it measures under a lamp
    for i = 1, 40 do
      local r = lab.meter.measure()
      lab.record("reading/" .. i, { quantity = "luminance", value = r.luminance, unit = r.unit, instrument = r.instrument })
      lab.wait(2)  -- long enough that the kill lands mid-run even on a loaded machine
    end
  end,
}
)lua");
  DaemonProcess daemon(dir / "state", config);
  auto api = api_for(daemon);
  auto e = start(api, "lit", json::object());
  std::string id = e["id"];
  wait_measurements(api, e, 3);
  daemon.kill9();
  std::ofstream(dir / "lab.toml") << "[genicam]\nenabled = false\n[dmx]\nserial = 22222222\n";
  daemon.start();
  api = api_for(daemon);
  auto paused = wait_status(api, id, "paused");
  ASSERT_EQ(paused["status"], "paused") << paused.dump();
  EXPECT_NE(paused["reason"].get<std::string>().find("dmx: the run started with serial"), std::string::npos) << paused.dump();
  api.post("/v1/executions/" + id + "/resume", json::object());
  auto done = wait_terminal(api, id);
  EXPECT_EQ(done["status"], "finished_ok") << done.dump();
  json run = colorlab::client::fetch_run(api, e["run_id"].get<std::string>());
  ASSERT_EQ(run["measurements"].size(), 40u);
  // The lamp was relit and waited for: no reading after the resume comes from a dark or cold lamp.
  double first = run["measurements"][0]["value"];
  EXPECT_GT(first, 100.0);
  for (const auto& m : run["measurements"]) EXPECT_NEAR(m["value"].get<double>(), first, 0.02 * first) << m["step"];
}

// lab.wait_stable against the simulator's lamp physics: a tube switched on starts at 85 % of its
// output and approaches it with a 120 s time constant (docs/simulator.md). The reading taken at
// once is low by about that much; the one after wait_stable is within the drift tolerance of the
// warm lamp, and the wait took the few time constants the drift criterion implies.
TEST(EngineInDaemon, WaitStableWaitsOutALampsWarmUp) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 40, 1));
  write_campaign(dir.path(), "warm.lua", R"lua(
return {
  needs = { "lamps", "dimmer", "luminance_meter" },
  run = function(p)
    lab.lamps.off()
    lab.dimmer.set(100)
    lab.wait(30)
    lab.lamps.select("TL84")
    lab.wait(2)  -- the widget's frame reaches the lamp; 2 s of warm-up change its output by 0.2 %
    local cold = lab.meter.measure()
    local s = lab.wait_stable({ tolerance_pct = 0.5, window_s = 60, interval_s = 5, timeout_s = 3600 })
    local warm = lab.meter.measure()
    return { cold = cold.luminance, warm = warm.luminance, waited_s = s.waited_s, drift_pct = s.drift_pct }
  end,
}
)lua");
  auto api = api_for(daemon);
  auto e = start(api, "warm", json::object());
  auto done = wait_terminal(api, e["id"], std::chrono::seconds(120));
  ASSERT_EQ(done["status"], "finished_ok") << done.dump();
  json r = colorlab::client::fetch_run(api, e["run_id"].get<std::string>())["summary"]["script"];
  double cold = r["cold"], warm = r["warm"], waited = r["waited_s"];
  EXPECT_NEAR(cold / warm, 0.85, 0.03) << r.dump();
  // Drift over 60 s below 0.5 % needs 0.15·e^(−t/120)·60/120 < 0.005, i.e. t > 2.7 τ ≈ 324 s.
  EXPECT_GT(waited, 250) << r.dump();
  EXPECT_LT(waited, 700) << r.dump();
  EXPECT_LE(r["drift_pct"].get<double>(), 0.5);
}

// The Spectrolino on its SpectroScan T after kill -9: the fresh driver has no white calibration and
// the head may be anywhere. The resumed run must calibrate again before it measures and take every
// patch where the uninterrupted run took it: each reading equals that run's within the
// instrument's noise (σ ≈ 0.001 + 0.2 % in reflectance, i.e. well under 1 in Y).
TEST(EngineInDaemon, ChartPatchesAfterAResumeEqualTheUninterruptedRunsWithinNoise) {
  const char* script = R"lua(
return {
  needs = { "spectrophotometer", "table" },
  run = function(p)
    lab.spectro.calibrate()
    for i = 0, 13 do
      local x, y = 24 + 14 * (i % 7), 16 + 14 * (i // 7)
      local s = lab.table.measure_at(x, y)
      lab.record(string.format("patch/%d", i), { quantity = "Y", value = s.XYZ[2], unit = "", instrument = s.instrument,
                                                 data = { XYZ = s.XYZ, x_mm = x, y_mm = y } })
    end
    lab.table.home()
  end,
}
)lua";
  auto run_it = [&](bool kill) {
    TempDir dir;
    DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 10, 1));
    write_campaign(dir.path(), "patches.lua", script);
    auto api = api_for(daemon);
    auto e = start(api, "patches", json::object());
    if (kill) {
      wait_measurements(api, e, 4);
      daemon.kill9();
      daemon.start();
      api = api_for(daemon);
    }
    auto done = wait_terminal(api, e["id"], std::chrono::seconds(120));
    EXPECT_EQ(done["status"], "finished_ok") << done.dump();
    json run = colorlab::client::fetch_run(api, e["run_id"].get<std::string>());
    json restored = nullptr;
    json events = api.get("/v1/events?topic=execution&limit=300");
    for (const auto& ev : events["items"]) {
      if (ev["payload"].contains("restored")) restored = ev["payload"]["restored"];
    }
    return std::make_pair(run, restored);
  };
  auto [reference, none] = run_it(false);
  auto [resumed, restored] = run_it(true);
  ASSERT_EQ(reference["measurements"].size(), 14u);
  ASSERT_EQ(resumed["measurements"].size(), 14u);
  for (std::size_t i = 0; i < 14; ++i) {
    EXPECT_EQ(resumed["measurements"][i]["step"], reference["measurements"][i]["step"]);
    EXPECT_NEAR(resumed["measurements"][i]["value"].get<double>(), reference["measurements"][i]["value"].get<double>(), 1.0)
        << resumed["measurements"][i]["step"];
  }
  // What the resume did before its first reading: head up, a new white calibration, back over the patch.
  ASSERT_TRUE(restored.is_array()) << "no restore was recorded";
  std::string what = restored.dump();
  EXPECT_NE(what.find("head up"), std::string::npos) << what;
  EXPECT_NE(what.find("white calibration"), std::string::npos) << what;
  EXPECT_NE(what.find("table_mm"), std::string::npos) << what;
}

// The same control from the CLI: each command returns once the execution has reached the state
// (pause and abort land at the next safe point), and a refused one exits 2 with the server's reason.
TEST(EngineInDaemon, CliPausesResumesAndAbortsAndSaysWhyItCannot) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 4, 1));
  auto cli = [&](std::vector<std::string> args) {
    std::vector<std::string> argv{bin_path("colorlab"), "--socket", daemon.unix_socket(), "--json"};
    argv.insert(argv.end(), args.begin(), args.end());
    return run_command(argv, std::chrono::seconds(60));
  };
  auto started = cli({"run", "luminance-spot", "-p", "readings=300", "--detach"});
  ASSERT_EQ(started.exit_code, 0) << started.err;
  std::string id = json::parse(started.out)["id"];
  auto paused = cli({"pause", id});
  ASSERT_EQ(paused.exit_code, 0) << paused.err;
  EXPECT_EQ(json::parse(paused.out)["status"], "paused");
  auto resumed = cli({"resume", id});
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_EQ(json::parse(resumed.out)["status"], "running");
  auto aborted = cli({"abort", id});
  ASSERT_EQ(aborted.exit_code, 0) << aborted.err;
  EXPECT_EQ(json::parse(aborted.out)["status"], "aborted");
  auto again = cli({"abort", id});
  EXPECT_EQ(again.exit_code, 2);
  EXPECT_NE(again.err.find("already ended"), std::string::npos) << again.err;
}
