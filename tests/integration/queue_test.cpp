// The night's queue in a real colorlabd on the simulated lab: items run one after another in
// order; a failed item halts the queue (on_failure = stop) or not (continue); the queue outlives
// the daemon — SIGTERM or kill -9 in the middle of an item, and after the restart the engine
// resumes that item's execution (it is not started twice) and the rest follow; autostart, and a
// halt that autostart does not override; a paused execution holds the queue and stop lets the
// running item finish; enqueue is validated exactly as a direct start; the CLI. An item that takes
// an earlier item's run ({"$run_of": id}, issue 11): it gets that run's id when it comes up, is skipped
// with the reason when the referenced item failed, a bad reference and a reorder are refused with typed
// 409s, and the reference survives kill -9 of the daemon during and between the two items.
#include <algorithm>
#include <fstream>
#include <functional>
#include <map>
#include <thread>

#include <gtest/gtest.h>

#include "colorlab/client/api_client.hpp"
#include "colorlab/client/runs.hpp"
#include "resume_support.hpp"

using namespace colorlab::testing;
using colorlab::client::ApiClient;
using colorlab::client::ApiError;
using nlohmann::json;

namespace {

const char* kDirtyTile = R"lua(
return {
  description = "a step that fails: the tile is dirty",
  needs = { "luminance_meter" },
  run = function(p)
    local r = lab.meter.measure()
    lab.record("before", { quantity = "luminance", value = r.luminance, unit = r.unit, instrument = r.instrument })
    error("the tile is dirty")
  end,
}
)lua";

// Records the run id it was given (its parameter source_run) with one reading.
const char* kTakesRun = R"lua(
return {
  description = "takes an earlier run",
  needs = { "luminance_meter" },
  parameters = { source_run = { type = "string", description = "a run id" } },
  run = function(p)
    local r = lab.meter.measure()
    lab.record("given", { quantity = "luminance", value = r.luminance, unit = r.unit, instrument = r.instrument,
                          data = { source_run = p.source_run } })
  end,
}
)lua";

// The problem a refused request answers with.
colorlab::protocol::Problem problem_of(const std::function<void()>& call) {
  try {
    call();
  } catch (const ApiError& e) {
    return e.problem();
  }
  ADD_FAILURE() << "accepted";
  return colorlab::protocol::Problem{};
}

json spot(int readings, double interval_s = 0) { return {{"readings", readings}, {"interval_s", interval_s}}; }

json enqueue(const ApiClient& api, const std::string& campaign, const json& params, const std::string& on_failure = "stop") {
  return api.post("/v1/queue", {{"campaign", campaign}, {"params", params}, {"on_failure", on_failure}});
}

json queue_of(const ApiClient& api) { return api.get("/v1/queue?history=300"); }

// Polls GET /v1/queue until `done` holds; returns the last answer (the caller's assertions say what was missing).
template <typename Pred>
json wait_queue(const ApiClient& api, Pred done, std::chrono::seconds timeout = std::chrono::seconds(120)) {
  auto deadline = std::chrono::steady_clock::now() + timeout;
  json q;
  while (std::chrono::steady_clock::now() < deadline) {
    q = queue_of(api);
    if (done(q)) return q;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return q;
}

bool emptied(const json& q) { return q["items"].empty(); }

json item_in(const json& q, const std::string& id) {
  for (const char* list : {"items", "history"}) {
    for (const auto& item : q[list]) {
      if (item["id"] == id) return item;
    }
  }
  return nullptr;
}

std::size_t run_count(const ApiClient& api) { return api.get("/v1/runs?limit=300")["items"].size(); }

json run_of(const ApiClient& api, const json& item) {
  auto execution = api.get("/v1/executions/" + item["execution_id"].get<std::string>());
  return colorlab::client::fetch_run(api, execution["run_id"].get<std::string>());
}

// Sequence numbers in the event log: when an execution was created and when it ended.
struct Span {
  std::int64_t created = -1, ended = -1;
};
std::map<std::string, Span> execution_spans(const ApiClient& api) {
  std::map<std::string, Span> out;
  json events = api.get("/v1/events?topic=execution&limit=300");
  for (const auto& e : events["items"]) {
    const auto& p = e["payload"];
    if (p.value("status", "") == "waiting" && p.contains("id")) out[p["id"]].created = e["seq"];
    if (p.contains("execution_id")) {
      auto status = p.value("status", "");
      if (status == "finished_ok" || status == "finished_error" || status == "aborted") out[p["execution_id"]].ended = e["seq"];
    }
  }
  return out;
}

std::size_t measurement_count(const ApiClient& api, const std::string& execution_id) {
  auto e = api.get("/v1/executions/" + execution_id);
  return colorlab::client::fetch_run(api, e["run_id"].get<std::string>())["measurements"].size();
}

// The running item's execution id once it has committed `n` measurements.
std::string wait_current_measurements(const ApiClient& api, std::size_t n) {
  for (int i = 0; i < 3000; ++i) {
    auto q = queue_of(api);
    if (q["current"].is_object()) {
      std::string id = q["current"]["execution_id"];
      if (measurement_count(api, id) >= n) return id;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return {};
}

}  // namespace

TEST(queue_daemon, ItemsRunOneAfterAnotherInOrderAndTheQueueEmpties) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 20, 1));
  auto api = api_for(daemon);
  std::vector<std::string> ids;
  for (int readings : {2, 3, 4}) {
    auto item = enqueue(api, "luminance-spot", spot(readings));
    EXPECT_EQ(item["state"], "queued");
    EXPECT_EQ(item["position"], ids.size() + 1);
    EXPECT_EQ(item["params"]["readings"], readings);
    ids.push_back(item["id"]);
  }
  auto stopped = queue_of(api);
  EXPECT_EQ(stopped["state"], "stopped");
  EXPECT_EQ(stopped["items"].size(), 3u);
  EXPECT_EQ(run_count(api), 0u) << "a stopped queue starts nothing";

  auto started = api.post("/v1/queue/start", json::object());
  EXPECT_EQ(started["state"], "running");
  auto q = wait_queue(api, emptied);
  ASSERT_TRUE(emptied(q)) << q.dump(1);
  EXPECT_EQ(q["state"], "running") << "a started queue stays started when it empties";
  EXPECT_TRUE(q["current"].is_null());

  auto spans = execution_spans(api);
  std::int64_t previous_end = -1;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    auto item = item_in(q, ids[i]);
    ASSERT_EQ(item["state"], "done") << item.dump();
    EXPECT_TRUE(item["position"].is_null());
    auto run = run_of(api, item);
    EXPECT_EQ(run["status"], "finished_ok");
    EXPECT_EQ(run["measurements"].size(), i + 2);
    const auto& span = spans[item["execution_id"].get<std::string>()];
    ASSERT_GE(span.created, 0);
    EXPECT_GT(span.created, previous_end) << "item " << i << " started before the one before it ended";
    previous_end = span.ended;
  }
  EXPECT_EQ(run_count(api), 3u);

  // Still started: an item added now runs without another start.
  auto late = enqueue(api, "luminance-spot", spot(1));
  q = wait_queue(api, emptied);
  EXPECT_EQ(item_in(q, late["id"].get<std::string>())["state"], "done") << q.dump(1);
}

TEST(queue_daemon, AFailedItemWithStopHaltsTheQueueUntilAnOperatorStartsItAgain) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 20, 1));
  write_campaign(dir.path(), "dirty-tile.lua", kDirtyTile);
  auto api = api_for(daemon);
  std::string first = enqueue(api, "luminance-spot", spot(2))["id"];
  std::string failing = enqueue(api, "dirty-tile", json::object(), "stop")["id"];
  std::string last = enqueue(api, "luminance-spot", spot(2))["id"];
  api.post("/v1/queue/start", json::object());
  auto q = wait_queue(api, [](const json& q) { return q["halted"] == true; });
  ASSERT_EQ(q["halted"], true) << q.dump(1);
  EXPECT_EQ(q["state"], "stopped");
  EXPECT_NE(q["reason"].get<std::string>().find(failing), std::string::npos) << q["reason"];
  EXPECT_NE(q["reason"].get<std::string>().find("on_failure is stop"), std::string::npos) << q["reason"];
  EXPECT_EQ(item_in(q, first)["state"], "done");
  auto failed = item_in(q, failing);
  EXPECT_EQ(failed["state"], "failed");
  EXPECT_NE(failed["reason"].get<std::string>().find("the tile is dirty"), std::string::npos) << failed.dump();
  EXPECT_EQ(api.get("/v1/executions/" + failed["execution_id"].get<std::string>())["status"], "finished_error");
  auto waiting = item_in(q, last);
  EXPECT_EQ(waiting["state"], "queued");
  EXPECT_EQ(waiting["position"], 1);
  EXPECT_TRUE(waiting["execution_id"].is_null());
  EXPECT_EQ(run_count(api), 2u) << "nothing after the failed item may start";

  auto restarted = api.post("/v1/queue/start", json::object());
  EXPECT_EQ(restarted["state"], "running");
  EXPECT_EQ(restarted["halted"], false);
  q = wait_queue(api, emptied);
  EXPECT_EQ(item_in(q, last)["state"], "done") << q.dump(1);
  EXPECT_EQ(item_in(q, failing)["state"], "failed") << "a failed item is not run again";
}

TEST(queue_daemon, AFailedItemWithContinueLetsTheQueueGoOn) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 20, 1));
  write_campaign(dir.path(), "dirty-tile.lua", kDirtyTile);
  auto api = api_for(daemon);
  std::string failing = enqueue(api, "dirty-tile", json::object(), "continue")["id"];
  std::string next = enqueue(api, "luminance-spot", spot(2))["id"];
  api.post("/v1/queue/start", json::object());
  auto q = wait_queue(api, emptied);
  ASSERT_TRUE(emptied(q)) << q.dump(1);
  EXPECT_EQ(item_in(q, failing)["state"], "failed");
  EXPECT_EQ(item_in(q, failing)["on_failure"], "continue");
  EXPECT_EQ(item_in(q, next)["state"], "done");
  EXPECT_EQ(q["state"], "running");
  EXPECT_EQ(q["halted"], false);
}

// The queue outlives the daemon: stopped by SIGTERM (the item's execution is suspended) or killed
// (-9, mid-step), the next daemon resumes the running item's execution — the same execution, the
// same run, every step once — and the queue follows it, then runs the rest.
class queue_restart : public ::testing::TestWithParam<const char*> {};

TEST_P(queue_restart, TheRunningItemResumesOnceAndTheRestFollow) {
  const bool sigterm = std::string(GetParam()) == "sigterm";
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 4, 1));
  auto api = api_for(daemon);
  std::string long_item = enqueue(api, "luminance-spot", spot(12, 1))["id"];
  std::string short_item = enqueue(api, "luminance-spot", spot(2))["id"];
  api.post("/v1/queue/start", json::object());
  std::string execution = wait_current_measurements(api, 3);
  ASSERT_FALSE(execution.empty()) << queue_of(api).dump(1);
  if (sigterm) {
    EXPECT_EQ(daemon.terminate(), 0);
  } else {
    daemon.kill9();
  }
  EXPECT_EQ(integrity_check(dir / "state"), "ok");
  daemon.start();
  api = api_for(daemon);
  auto q = wait_queue(api, emptied);
  ASSERT_TRUE(emptied(q)) << q.dump(1);

  auto resumed = item_in(q, long_item);
  EXPECT_EQ(resumed["state"], "done") << resumed.dump();
  EXPECT_EQ(resumed["execution_id"], execution) << "the item must continue as the execution it started";
  EXPECT_EQ(item_in(q, short_item)["state"], "done");
  EXPECT_EQ(run_count(api), 2u) << "the running item was started twice";
  auto run = run_of(api, resumed);
  ASSERT_EQ(run["measurements"].size(), 12u);
  for (int i = 0; i < 12; ++i) EXPECT_EQ(run["measurements"][i]["step"], "reading/" + std::to_string(i));

  bool engine_resumed = false, suspended = false;
  json events = api.get("/v1/events?topic=execution&limit=300");
  for (const auto& e : events["items"]) {
    if (e["payload"].value("execution_id", "") != execution) continue;
    if (e["payload"].value("resumed", false)) engine_resumed = true;
    if (e["payload"].value("status", "") == "suspended") suspended = true;
  }
  EXPECT_TRUE(engine_resumed) << "the engine, not the queue, must have continued the execution";
  EXPECT_EQ(suspended, sigterm);
  auto spans = execution_spans(api);
  auto second = item_in(q, short_item)["execution_id"].get<std::string>();
  EXPECT_GT(spans[second].created, spans[execution].ended) << "the next item started before the resumed one ended";
}

INSTANTIATE_TEST_SUITE_P(queue_daemon, queue_restart, ::testing::Values("sigterm", "kill9"),
                         [](const auto& info) { return std::string(info.param); });

TEST(queue_daemon, AutostartStartsTheQueueWithTheDaemonButNotAfterAHalt) {
  TempDir dir;
  auto config = write_daemon_config(dir.path(), 20, 1, "[queue]\nautostart = true\n");
  DaemonProcess daemon(dir / "state", config);
  write_campaign(dir.path(), "dirty-tile.lua", kDirtyTile);
  auto api = api_for(daemon);
  auto q = queue_of(api);
  EXPECT_EQ(q["state"], "running");
  EXPECT_EQ(q["autostart"], true);
  EXPECT_NE(q["reason"].get<std::string>().find("autostart"), std::string::npos) << q["reason"];
  std::string first = enqueue(api, "luminance-spot", spot(1))["id"];
  std::string failing = enqueue(api, "dirty-tile", json::object())["id"];
  std::string after = enqueue(api, "luminance-spot", spot(1))["id"];
  q = wait_queue(api, [](const json& q) { return q["halted"] == true; });
  ASSERT_EQ(q["halted"], true) << q.dump(1);
  EXPECT_EQ(item_in(q, first)["state"], "done");

  EXPECT_EQ(daemon.terminate(), 0);
  daemon.start();
  api = api_for(daemon);
  q = queue_of(api);
  EXPECT_EQ(q["state"], "stopped") << "autostart must not override a halt: " << q.dump(1);
  EXPECT_EQ(q["halted"], true);
  std::this_thread::sleep_for(std::chrono::seconds(1));  // several polls of the queue
  EXPECT_EQ(item_in(queue_of(api), after)["state"], "queued");
  EXPECT_EQ(run_count(api), 2u);

  api.post("/v1/queue/start", json::object());
  q = wait_queue(api, emptied);
  EXPECT_EQ(item_in(q, after)["state"], "done") << q.dump(1);
}

TEST(queue_daemon, APausedItemHoldsTheQueueAndStopLetsTheRunningItemFinish) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 4, 1));
  auto api = api_for(daemon);
  std::string long_item = enqueue(api, "luminance-spot", spot(40))["id"];
  std::string next = enqueue(api, "luminance-spot", spot(1))["id"];
  api.post("/v1/queue/start", json::object());
  std::string execution = wait_current_measurements(api, 2);
  ASSERT_FALSE(execution.empty());
  api.post("/v1/executions/" + execution + "/pause", json::object());
  auto q = wait_queue(
      api, [](const json& q) { return q["current"].value("execution_status", "") == "paused"; },
      std::chrono::seconds(30));
  ASSERT_EQ(q["current"]["execution_status"], "paused") << q.dump(1);
  std::this_thread::sleep_for(std::chrono::seconds(1));  // several polls of the queue
  q = queue_of(api);
  EXPECT_EQ(item_in(q, next)["state"], "queued") << "a paused execution must hold the queue";
  EXPECT_EQ(run_count(api), 1u);

  auto stopping = api.post("/v1/queue/stop", json::object());
  EXPECT_EQ(stopping["state"], "stopping");
  EXPECT_EQ(stopping["reason"], "stopped by a client");
  api.post("/v1/executions/" + execution + "/resume", json::object());
  auto done = wait_terminal(api, execution);
  EXPECT_EQ(done["status"], "finished_ok") << "stop must not abort the running item: " << done.dump();
  q = wait_queue(api, [](const json& q) { return q["state"] == "stopped"; });
  EXPECT_EQ(q["state"], "stopped");
  EXPECT_EQ(item_in(q, long_item)["state"], "done");
  EXPECT_EQ(item_in(q, next)["state"], "queued");
  EXPECT_EQ(run_count(api), 1u) << "a stopped queue starts nothing more";
}

// The lab has one set of instruments: a run started by hand holds the queue as much as its own items, and
// refuses a second start by hand (409 lab-busy naming it) while a retry of its own POST still gets it back.
TEST(queue_daemon, ARunStartedByHandHoldsTheQueueUntilItEnds) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 4, 1));
  auto api = api_for(daemon);
  const json body{{"campaign", "luminance-spot"}, {"params", spot(400)}};
  auto started = api.request("POST", "/v1/executions", body.dump(), {{"Idempotency-Key", "by-hand-1"}});
  ASSERT_EQ(started.status, 202) << started.body;
  std::string manual_id = json::parse(started.body)["id"];
  auto retried = api.request("POST", "/v1/executions", body.dump(), {{"Idempotency-Key", "by-hand-1"}});
  EXPECT_EQ(retried.status, 202) << retried.body;
  EXPECT_EQ(json::parse(retried.body)["id"], manual_id) << "a retried POST is the same execution, not a busy lab";
  auto second = problem_of([&] { api.post("/v1/executions", {{"campaign", "luminance-spot"}, {"params", spot(1)}}); });
  EXPECT_EQ(second.status, 409);
  EXPECT_EQ(second.code, "lab-busy");
  EXPECT_NE(second.detail.find(manual_id), std::string::npos) << second.detail;
  EXPECT_FALSE(second.hint.empty());
  EXPECT_EQ(run_count(api), 1u) << "the refused start stored a run";
  std::string item = enqueue(api, "luminance-spot", spot(1))["id"];
  api.post("/v1/queue/start", json::object());
  auto q = wait_queue(
      api, [](const json& q) { return !q["waiting_for"].is_null(); }, std::chrono::seconds(30));
  EXPECT_EQ(q["waiting_for"], manual_id) << q.dump(1);
  std::this_thread::sleep_for(std::chrono::seconds(1));  // several polls of the queue
  EXPECT_EQ(item_in(queue_of(api), item)["state"], "queued") << "an item started beside a running execution";
  api.post("/v1/executions/" + manual_id + "/abort", json::object());
  EXPECT_EQ(wait_terminal(api, manual_id)["status"], "aborted");
  q = wait_queue(api, emptied);
  EXPECT_EQ(item_in(q, item)["state"], "done") << q.dump(1);
  auto spans = execution_spans(api);
  EXPECT_GT(spans[item_in(q, item)["execution_id"].get<std::string>()].created, spans[manual_id].ended);
}

TEST(queue_daemon, EnqueueIsValidatedExactlyAsADirectStartAndErrorsStoreNothing) {
  TempDir dir;
  auto config = write_daemon_config(dir.path(), 20, 1);
  // A lab without the spectrophotometer, for a campaign that needs one.
  std::ofstream(dir / "lab.toml") << "[genicam]\nenabled = false\n[spectrolino]\nenabled = false\n";
  DaemonProcess daemon(dir / "state", config);
  write_campaign(dir.path(), "chart.lua", "return { needs = { \"spectrophotometer\" }, run = function(p) lab.spectro.calibrate() end }\n");
  auto api = api_for(daemon);
  // The same request refused the same way by POST /v1/executions and POST /v1/queue.
  const json requests[] = {
      {{"campaign", "no-such-campaign"}, {"params", json::object()}},
      {{"campaign", "luminance-spot"}, {"params", {{"readings", 0}}}},
      {{"campaign", "luminance-spot"}, {"params", {{"readings", 1}, {"colour", "red"}}}},
      {{"campaign", "chart"}, {"params", json::object()}},
  };
  for (const auto& request : requests) {
    SCOPED_TRACE(request.dump());
    auto direct = problem_of([&] { api.post("/v1/executions", request); });
    auto queued = problem_of([&] { api.post("/v1/queue", request); });
    EXPECT_GE(queued.status, 400);
    EXPECT_EQ(queued.status, direct.status);
    EXPECT_EQ(queued.code, direct.code);
    EXPECT_EQ(queued.detail, direct.detail);
    EXPECT_EQ(queued.hint, direct.hint);
  }
  EXPECT_NE(problem_of([&] { api.post("/v1/queue", requests[1]); }).detail.find("params.readings"), std::string::npos);
  auto bad_policy = problem_of([&] { enqueue(api, "luminance-spot", spot(1), "retry"); });
  EXPECT_EQ(bad_policy.status, 400);
  EXPECT_EQ(bad_policy.code, "bad_parameter");
  EXPECT_FALSE(bad_policy.hint.empty());
  EXPECT_EQ(problem_of([&] { api.post("/v1/queue", {{"params", spot(1)}}); }).status, 400);
  EXPECT_EQ(api.request("POST", "/v1/queue", "{not json", {{"Content-Type", "application/json"}}).status, 400);
  EXPECT_EQ(api.request("POST", "/v1/queue", "campaign=x", {{"Content-Type", "text/plain"}}).status, 415);
  EXPECT_EQ(problem_of([&] { api.get("/v1/queue/0190aaaa-0000-7000-8000-000000000000"); }).status, 404);
  EXPECT_EQ(problem_of([&] { api.del("/v1/queue/0190aaaa-0000-7000-8000-000000000000"); }).code, "not_found");
  EXPECT_EQ(api.request("GET", "/v1/queue/start").status, 405);
  EXPECT_EQ(problem_of([&] { api.get("/v1/queue?history=abc"); }).status, 400);
  auto q = queue_of(api);
  EXPECT_TRUE(q["items"].empty()) << q.dump(1);
  EXPECT_TRUE(q["history"].empty()) << q.dump(1);
  EXPECT_EQ(run_count(api), 0u);

  // A retried enqueue with the same Idempotency-Key queues once.
  json body{{"campaign", "luminance-spot"}, {"params", spot(1)}};
  auto first = api.request("POST", "/v1/queue", body.dump(), {{"Idempotency-Key", "night-1"}});
  auto again = api.request("POST", "/v1/queue", body.dump(), {{"Idempotency-Key", "night-1"}});
  EXPECT_EQ(first.status, 201);
  EXPECT_EQ(again.status, 200);
  EXPECT_EQ(json::parse(first.body)["id"], json::parse(again.body)["id"]);
  EXPECT_EQ(first.headers["Location"], "/v1/queue/" + json::parse(first.body)["id"].get<std::string>());
  EXPECT_EQ(queue_of(api)["items"].size(), 1u);
  // Defaults are filled in at enqueue, as a run stores them; on_failure defaults to stop.
  auto stored = json::parse(first.body);
  EXPECT_EQ(stored["params"]["interval_s"], 0);
  EXPECT_EQ(stored["on_failure"], "stop");
}

TEST(queue_daemon, CliAddsListsMovesRemovesStartsAndStops) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 20, 1));
  auto cli = [&](std::vector<std::string> args) {
    std::vector<std::string> argv{bin_path("colorlab"), "--socket", daemon.unix_socket()};
    argv.insert(argv.end(), args.begin(), args.end());
    return run_command(argv, std::chrono::seconds(60));
  };
  auto add = [&](std::vector<std::string> extra) {
    std::vector<std::string> args{"--json", "queue", "add", "luminance-spot"};
    args.insert(args.end(), extra.begin(), extra.end());
    auto r = cli(args);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return json::parse(r.out);
  };
  auto a = add({"-p", "readings=2"});
  auto b = add({"-p", "readings=1", "--on-failure", "continue"});
  auto c = add({"--param", "readings=3", "-p", "interval_s=0.5"});
  EXPECT_EQ(b["on_failure"], "continue");
  EXPECT_EQ(c["params"]["interval_s"], 0.5);
  EXPECT_EQ(c["position"], 3);
  auto refused = cli({"queue", "add", "luminance-spot", "-p", "readings=0"});
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("params.readings"), std::string::npos) << refused.err;
  EXPECT_NE(cli({"queue", "add", "luminance-spot", "--on-failure", "retry"}).exit_code, 0);

  auto moved = cli({"--json", "queue", "move", c["id"].get<std::string>(), "1"});
  ASSERT_EQ(moved.exit_code, 0) << moved.err;
  EXPECT_EQ(json::parse(moved.out)["position"], 1);
  auto removed = cli({"--json", "queue", "remove", b["id"].get<std::string>()});
  ASSERT_EQ(removed.exit_code, 0) << removed.err;
  EXPECT_EQ(json::parse(removed.out)["state"], "removed");
  auto list = cli({"queue", "list"});
  ASSERT_EQ(list.exit_code, 0) << list.err;
  EXPECT_NE(list.out.find("queue stopped"), std::string::npos) << list.out;
  auto at_c = list.out.find(c["id"].get<std::string>()), at_a = list.out.find(a["id"].get<std::string>());
  ASSERT_NE(at_c, std::string::npos) << list.out;
  ASSERT_NE(at_a, std::string::npos) << list.out;
  EXPECT_LT(at_c, at_a) << "the moved item is listed first: " << list.out;

  auto started = cli({"--json", "queue", "start"});
  ASSERT_EQ(started.exit_code, 0) << started.err;
  EXPECT_EQ(json::parse(started.out)["state"], "running");
  auto api = api_for(daemon);
  auto q = wait_queue(api, emptied);
  ASSERT_TRUE(emptied(q)) << q.dump(1);
  EXPECT_EQ(item_in(q, b["id"].get<std::string>())["state"], "removed");
  EXPECT_TRUE(item_in(q, b["id"].get<std::string>())["execution_id"].is_null()) << "a removed item never runs";
  std::vector<std::string> started_order;
  json events = api.get("/v1/events?topic=queue&limit=300");
  for (const auto& e : events["items"]) {
    if (e["payload"].value("change", "") == "started") started_order.push_back(e["payload"]["item"]["id"]);
  }
  EXPECT_EQ(started_order, (std::vector<std::string>{c["id"].get<std::string>(), a["id"].get<std::string>()}));

  auto too_late = cli({"queue", "remove", a["id"].get<std::string>()});
  EXPECT_EQ(too_late.exit_code, 2);
  EXPECT_NE(too_late.err.find("not queued"), std::string::npos) << too_late.err;
  auto stopped = cli({"--json", "queue", "stop"});
  ASSERT_EQ(stopped.exit_code, 0) << stopped.err;
  EXPECT_EQ(json::parse(stopped.out)["state"], "stopped");
}

namespace {

json run_of_item(const std::string& item_id) { return {{"source_run", {{"$run_of", item_id}}}}; }

std::string run_id_of(const ApiClient& api, const json& item) {
  return api.get("/v1/executions/" + item["execution_id"].get<std::string>())["run_id"];
}

// The source_run the takes-run item's campaign was given, as it recorded it.
std::string recorded_source_run(const ApiClient& api, const json& item) {
  auto run = run_of(api, item);
  if (run["measurements"].empty()) return {};
  return run["measurements"][0]["data"].value("source_run", std::string());
}

}  // namespace

TEST(queue_references, AnItemGetsTheRunOfTheItemItReferencesWhenItComesUp) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 20, 1));
  write_campaign(dir.path(), "takes-run.lua", kTakesRun);
  auto api = api_for(daemon);
  std::string first = enqueue(api, "luminance-spot", spot(2))["id"];
  std::string other = enqueue(api, "luminance-spot", spot(1))["id"];
  auto taker = enqueue(api, "takes-run", run_of_item(first));
  EXPECT_EQ(taker["params"]["source_run"], json({{"$run_of", first}})) << "unresolved while queued";
  EXPECT_EQ(taker["param_refs"]["source_run"], first);
  api.post("/v1/queue/start", json::object());
  auto q = wait_queue(api, emptied);
  ASSERT_TRUE(emptied(q)) << q.dump(1);
  auto done = item_in(q, taker["id"]);
  ASSERT_EQ(done["state"], "done") << done.dump(1);
  std::string first_run = run_id_of(api, item_in(q, first));
  EXPECT_NE(first_run, run_id_of(api, item_in(q, other)));
  EXPECT_EQ(done["params"]["source_run"], first_run) << "the item keeps its resolved parameter";
  EXPECT_EQ(done["param_refs"]["source_run"], first);
  EXPECT_EQ(recorded_source_run(api, done), first_run) << "the campaign must have been given the run id";
}

TEST(queue_references, AnItemWhoseReferenceFailedDoesNotStartAndTheItemsPolicyApplies) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 20, 1));
  write_campaign(dir.path(), "dirty-tile.lua", kDirtyTile);
  write_campaign(dir.path(), "takes-run.lua", kTakesRun);
  auto api = api_for(daemon);
  std::string failing = enqueue(api, "dirty-tile", json::object(), "continue")["id"];
  std::string taker = enqueue(api, "takes-run", run_of_item(failing), "stop")["id"];
  std::string last = enqueue(api, "luminance-spot", spot(1))["id"];
  api.post("/v1/queue/start", json::object());
  auto q = wait_queue(api, [](const json& q) { return q["halted"] == true; });
  ASSERT_EQ(q["halted"], true) << q.dump(1);
  EXPECT_EQ(item_in(q, failing)["state"], "failed");
  auto skipped = item_in(q, taker);
  EXPECT_EQ(skipped["state"], "skipped") << skipped.dump(1);
  EXPECT_TRUE(skipped["execution_id"].is_null()) << "it must not start";
  std::string reason = skipped["reason"];
  EXPECT_NE(reason.find(failing), std::string::npos) << reason;
  EXPECT_NE(reason.find("failed"), std::string::npos) << reason;
  EXPECT_NE(reason.find("source_run"), std::string::npos) << reason;
  EXPECT_NE(q["reason"].get<std::string>().find(taker), std::string::npos) << "its on_failure = stop halts the queue";
  EXPECT_EQ(item_in(q, last)["state"], "queued");
  EXPECT_EQ(run_count(api), 1u);

  // A removed reference: the item is skipped the same way; with continue the queue goes on.
  std::string removed = enqueue(api, "luminance-spot", spot(1))["id"];
  std::string orphan = enqueue(api, "takes-run", run_of_item(removed), "continue")["id"];
  api.del("/v1/queue/" + removed);
  api.post("/v1/queue/start", json::object());
  q = wait_queue(api, emptied);
  ASSERT_TRUE(emptied(q)) << q.dump(1);
  EXPECT_EQ(item_in(q, orphan)["state"], "skipped");
  EXPECT_NE(item_in(q, orphan)["reason"].get<std::string>().find("removed"), std::string::npos);
  EXPECT_EQ(item_in(q, last)["state"], "done");
  EXPECT_EQ(q["halted"], false);
}

TEST(queue_references, ABadReferenceAndAReorderBeforeTheReferenceAreRefusedWithTypedCodes) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 20, 1));
  write_campaign(dir.path(), "takes-run.lua", kTakesRun);
  auto api = api_for(daemon);
  auto unknown = problem_of([&] { enqueue(api, "takes-run", run_of_item("0190aaaa-0000-7000-8000-000000000000")); });
  EXPECT_EQ(unknown.status, 409);
  EXPECT_EQ(unknown.code, "queue-reference-unknown");
  EXPECT_FALSE(unknown.hint.empty());
  auto malformed = problem_of([&] { enqueue(api, "takes-run", {{"source_run", {{"$run_of", 7}}}}); });
  EXPECT_EQ(malformed.status, 400);
  std::string a = enqueue(api, "luminance-spot", spot(1))["id"];
  auto not_a_string = problem_of([&] { enqueue(api, "luminance-spot", {{"readings", {{"$run_of", a}}}}); });
  EXPECT_EQ(not_a_string.status, 400) << not_a_string.detail;
  std::string b = enqueue(api, "luminance-spot", spot(1))["id"];
  std::string c = enqueue(api, "takes-run", run_of_item(a))["id"];
  auto early = problem_of([&] { api.post("/v1/queue/" + c + "/move", {{"position", 1}}); });
  EXPECT_EQ(early.status, 409);
  EXPECT_EQ(early.code, "queue-reference-order");
  EXPECT_NE(early.detail.find(a), std::string::npos) << early.detail;
  EXPECT_EQ(problem_of([&] { api.post("/v1/queue/" + a + "/move", {{"position", 3}}); }).code, "queue-reference-order");
  auto q = queue_of(api);
  ASSERT_EQ(q["items"].size(), 3u);
  EXPECT_EQ(q["items"][0]["id"], a);
  EXPECT_EQ(q["items"][2]["id"], c);
  EXPECT_EQ(api.post("/v1/queue/" + c + "/move", {{"position", 2}})["position"], 2) << "after its reference is fine";
  EXPECT_EQ(run_count(api), 0u);
}

// kill -9 while the referenced item runs, and again between the two items (the first done, the queue
// stopped before the second): the next daemon gives the second item the first one's run.
TEST(queue_references, TheReferenceSurvivesKillNineDuringAndBetweenTheItems) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 4, 1));
  write_campaign(dir.path(), "takes-run.lua", kTakesRun);
  auto api = api_for(daemon);
  std::string first = enqueue(api, "luminance-spot", spot(8, 1))["id"];
  std::string taker = enqueue(api, "takes-run", run_of_item(first))["id"];
  api.post("/v1/queue/start", json::object());
  ASSERT_FALSE(wait_current_measurements(api, 2).empty()) << queue_of(api).dump(1);
  daemon.kill9();
  EXPECT_EQ(integrity_check(dir / "state"), "ok");
  daemon.start();
  api = api_for(daemon);
  auto q = wait_queue(api, emptied);
  ASSERT_TRUE(emptied(q)) << q.dump(1);
  std::string first_run = run_id_of(api, item_in(q, first));
  EXPECT_EQ(item_in(q, taker)["state"], "done");
  EXPECT_EQ(item_in(q, taker)["params"]["source_run"], first_run);
  EXPECT_EQ(recorded_source_run(api, item_in(q, taker)), first_run);

  // Between: the queue (still started) runs a second item and is stopped while it runs, so the item that
  // takes its run waits in the stopped queue; kill -9 then.
  std::string second = enqueue(api, "luminance-spot", spot(3, 0.5))["id"];
  q = wait_queue(api, [&](const json& q) { return item_in(q, second)["state"] != "queued"; });
  ASSERT_EQ(item_in(q, second)["state"], "running") << q.dump(1);
  api.post("/v1/queue/stop", json::object());
  std::string second_taker = enqueue(api, "takes-run", run_of_item(second))["id"];
  q = wait_queue(api, [&](const json& q) { return item_in(q, second)["state"] == "done"; });
  ASSERT_EQ(item_in(q, second)["state"], "done") << q.dump(1);
  ASSERT_EQ(item_in(q, second_taker)["state"], "queued") << "the stopped queue must not have started it";
  daemon.kill9();
  daemon.start();
  api = api_for(daemon);
  api.post("/v1/queue/start", json::object());
  q = wait_queue(api, emptied);
  ASSERT_TRUE(emptied(q)) << q.dump(1);
  std::string second_run = run_id_of(api, item_in(q, second));
  EXPECT_EQ(item_in(q, second_taker)["params"]["source_run"], second_run);
  EXPECT_EQ(recorded_source_run(api, item_in(q, second_taker)), second_run);
}

namespace {

// A lab's own sequence: a reading, then a campaign that takes that reading's run.
const char* kPairSequence = R"lua(
return {
  description = "a reading and the run that takes it",
  steps = {
    { name = "first", campaign = "luminance-spot", params = { readings = 3 } },
    { name = "second", campaign = "takes-run", reference = { param = "source_run", step = "first" } },
  },
  small = { first = { readings = 1 } },
}
)lua";

}  // namespace

// A sequence of the catalogue (issue 11): listed by GET /v1/campaigns with kind "sequence"; POST
// /v1/queue {"sequence"} (or "campaign" naming it) queues every step at once as a group whose items
// reference each other's item ids; small and per-step overrides apply; a retry with the same key
// returns the group; the group's route lists its runs once they ran; bad overrides are refused and
// nothing is stored.
TEST(queue_sequences, ASequenceIsQueuedAtOnceAsAGroupAndItsRunsAreListed) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 20, 1));
  write_campaign(dir.path(), "takes-run.lua", kTakesRun);
  write_campaign(dir.path(), "pair.sequence.lua", kPairSequence);
  auto api = api_for(daemon);
  json listed;
  const json catalogue = api.get("/v1/campaigns");
  for (const auto& c : catalogue["items"]) {
    if (c["name"] == "pair") listed = c;
  }
  ASSERT_TRUE(listed.is_object());
  EXPECT_EQ(listed["kind"], "sequence");
  EXPECT_EQ(listed["steps"].size(), 2u);
  EXPECT_EQ(listed["steps"][1]["reference"]["step"], "first");
  EXPECT_EQ(listed["small"]["first"]["readings"], 1);

  EXPECT_EQ(problem_of([&] { api.post("/v1/queue", {{"sequence", "pair"}, {"overrides", {{"third", {{"x", 1}}}}}}); })
                .status,
            400);
  auto refused = problem_of([&] { api.post("/v1/queue", {{"sequence", "pair"}, {"overrides", {{"first", {{"readings", 0}}}}}}); });
  EXPECT_EQ(refused.status, 400);
  EXPECT_NE(refused.detail.find("step 'first'"), std::string::npos) << refused.detail;
  EXPECT_EQ(problem_of([&] { api.post("/v1/queue", {{"sequence", "nope"}}); }).status, 404);
  EXPECT_EQ(problem_of([&] { api.post("/v1/queue", {{"sequence", "pair"}, {"small", "yes"}}); }).status, 400);
  EXPECT_TRUE(queue_of(api)["items"].empty()) << "a refused sequence stores nothing";

  json body{{"sequence", "pair"}, {"small", true}, {"overrides", {{"second", json::object()}}}};
  auto created = api.request("POST", "/v1/queue", body.dump(), {{"Idempotency-Key", "night-2"}});
  ASSERT_EQ(created.status, 201) << created.body;
  auto group = json::parse(created.body);
  EXPECT_EQ(created.headers["Location"], "/v1/queue/groups/" + group["id"].get<std::string>());
  auto again = api.request("POST", "/v1/queue", body.dump(), {{"Idempotency-Key", "night-2"}});
  EXPECT_EQ(again.status, 200);
  EXPECT_EQ(json::parse(again.body)["id"], group["id"]);
  EXPECT_EQ(group["sequence"], "pair");
  EXPECT_EQ(group["state"], "queued");
  ASSERT_EQ(group["items"].size(), 2u);
  const auto& first = group["items"][0];
  const auto& second = group["items"][1];
  EXPECT_EQ(first["step"], "first");
  EXPECT_EQ(first["params"]["readings"], 1) << "the small variant";
  EXPECT_EQ(second["group_id"], group["id"]);
  EXPECT_EQ(second["param_refs"]["source_run"], first["id"]);
  EXPECT_EQ(second["params"]["source_run"], json({{"$run_of", first["id"]}}));
  // "campaign" naming the sequence queues it too (colorlab queue add pair).
  auto by_campaign = api.post("/v1/queue", {{"campaign", "pair"}});
  EXPECT_EQ(by_campaign["items"].size(), 2u);
  EXPECT_EQ(by_campaign["items"][0]["params"]["readings"], 3) << "not small unless asked";
  EXPECT_EQ(queue_of(api)["items"].size(), 4u);
  api.del("/v1/queue/" + by_campaign["items"][0]["id"].get<std::string>());

  api.post("/v1/queue/start", json::object());
  auto q = wait_queue(api, emptied);
  ASSERT_TRUE(emptied(q)) << q.dump(1);
  auto ran = api.get("/v1/queue/groups/" + group["id"].get<std::string>());
  EXPECT_EQ(ran["state"], "done") << ran.dump(1);
  ASSERT_EQ(ran["run_ids"].size(), 2u);
  EXPECT_EQ(ran["runs"]["first"], ran["run_ids"][0]);
  EXPECT_EQ(ran["items"][0]["run_id"], ran["run_ids"][0]);
  EXPECT_EQ(recorded_source_run(api, ran["items"][1]), ran["run_ids"][0]);
  // The study's report: one file of the group's runs, made by the daemon (202 until made).
  const std::string report = "/v1/queue/groups/" + group["id"].get<std::string>() + "/report";
  EXPECT_EQ(ran["links"]["report"], report);
  auto made = api.request("GET", report);
  for (int i = 0; i < 600 && made.status == 202; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    made = api.request("GET", report);
  }
  ASSERT_EQ(made.status, 200) << made.body;
  EXPECT_NE(made.headers["Content-Type"].find("text/html"), std::string::npos);
  for (const auto& run : ran["run_ids"]) {
    EXPECT_NE(made.body.find("data-run=\"" + run.get<std::string>() + "\""), std::string::npos) << run;
  }
  auto orphaned = api.get("/v1/queue/groups/" + by_campaign["id"].get<std::string>());
  EXPECT_EQ(orphaned["state"], "failed") << "its first step was removed, so its second was skipped";
  EXPECT_EQ(orphaned["items"][1]["state"], "skipped");
  EXPECT_FALSE(orphaned.contains("links")) << "no run finished, so no report";
  EXPECT_EQ(problem_of([&] { api.get("/v1/queue/groups/" + by_campaign["id"].get<std::string>() + "/report"); }).status,
            409);
  EXPECT_EQ(problem_of([&] { api.get("/v1/queue/groups/0190aaaa-0000-7000-8000-000000000000"); }).status, 404);
}

TEST(queue_sequences, TheCliRunsASequenceToItsEndAndListsIt) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 20, 1));
  write_campaign(dir.path(), "takes-run.lua", kTakesRun);
  write_campaign(dir.path(), "pair.sequence.lua", kPairSequence);
  auto cli = [&](std::vector<std::string> args) {
    std::vector<std::string> argv{bin_path("colorlab"), "--socket", daemon.unix_socket()};
    argv.insert(argv.end(), args.begin(), args.end());
    return run_command(argv, std::chrono::seconds(60));
  };
  auto campaigns = cli({"campaigns"});
  ASSERT_EQ(campaigns.exit_code, 0) << campaigns.err;
  EXPECT_NE(campaigns.out.find("pair  (sequence, lab)"), std::string::npos) << campaigns.out;
  EXPECT_NE(campaigns.out.find("source_run = the run of first"), std::string::npos) << campaigns.out;

  auto run = cli({"--json", "run", "pair", "--small", "-p", "first.interval_s=0.1"});
  ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
  auto group = json::parse(run.out);
  EXPECT_EQ(group["state"], "done");
  ASSERT_EQ(group["run_ids"].size(), 2u);
  EXPECT_EQ(group["items"][0]["params"]["interval_s"], 0.1);
  EXPECT_EQ(group["items"][1]["params"]["source_run"], group["run_ids"][0]);

  auto ids = cli({"run", "pair", "--id-only"});
  ASSERT_EQ(ids.exit_code, 0) << ids.err;
  EXPECT_EQ(std::count(ids.out.begin(), ids.out.end(), '\n'), 2) << ids.out;
  auto plain = cli({"run", "pair", "--small"});
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_NE(plain.out.find("report  /v1/queue/groups/"), std::string::npos) << "the study's report is named: " << plain.out;

  auto queued = cli({"queue", "add", "pair", "-p", "second.source_run=x"});
  EXPECT_EQ(queued.exit_code, 2) << "a reference is the sequence's to fill in: " << queued.err;
  EXPECT_NE(cli({"queue", "add", "pair", "-p", "nodot=1"}).exit_code, 0);
  EXPECT_NE(cli({"queue", "add", "luminance-spot", "--small"}).exit_code, 0);
  auto added = cli({"queue", "add", "pair", "--small"});
  ASSERT_EQ(added.exit_code, 0) << added.err;
  EXPECT_NE(added.out.find("source_run ←"), std::string::npos) << added.out;
}
