// Live events over Server-Sent Events, read by curl (an independent HTTP and chunked-encoding
// client) from a real colorlabd on the simulated lab: a fresh stream begins with a snapshot, a
// stream resumed with Last-Event-ID after a kill -9 and restart of the daemon mid-campaign
// continues with no event lost and none repeated — the truth being the event log as the plain
// JSON route pages it. Also: a run's measurements paged and filtered, the run document small.
#include <map>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "colorlab/client/api_client.hpp"
#include "colorlab/client/runs.hpp"
#include "colorlab/testing/process.hpp"
#include "lab_fixture.hpp"

using colorlab::client::ApiClient;
using colorlab::client::Endpoint;
using colorlab::testing::LabFixture;
using nlohmann::json;

namespace {

struct SseEvent {
  std::string id;
  std::string event;
  std::string data;
};

// Per the WHATWG rules the stream uses: fields until a blank line; comments start with ':'.
std::vector<SseEvent> parse_sse(const std::string& text) {
  std::vector<SseEvent> out;
  SseEvent current;
  bool any = false;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) {
      if (any && !current.data.empty()) out.push_back(current);
      current = {};
      any = false;
      continue;
    }
    if (line[0] == ':') continue;
    auto colon = line.find(':');
    std::string field = line.substr(0, colon);
    std::string value = colon == std::string::npos ? "" : line.substr(colon + 1);
    if (!value.empty() && value[0] == ' ') value.erase(0, 1);
    if (field == "id") current.id = value, any = true;
    if (field == "event") current.event = value, any = true;
    if (field == "data") current.data += (current.data.empty() ? "" : "\n") + value, any = true;
  }
  return out;  // an unterminated last event is not an event
}

std::vector<SseEvent> read_stream(const std::string& url, double seconds, const std::string& last_event_id = {}) {
  std::vector<std::string> argv{"/usr/bin/curl", "-sN", "--max-time", std::to_string(seconds), url + "/v1/events/stream"};
  if (!last_event_id.empty()) {
    argv.push_back("-H");
    argv.push_back("Last-Event-ID: " + last_event_id);
  }
  auto r = colorlab::testing::run_command(argv, std::chrono::seconds(static_cast<int>(seconds) + 30));
  return parse_sse(r.out);
}

// The event log as the JSON route pages it: the independent record the stream must match.
std::vector<json> event_log(const ApiClient& api, std::int64_t after) {
  std::vector<json> all;
  for (;;) {
    json page = api.get("/v1/events?limit=300&after=" + std::to_string(after));
    for (auto& e : page["items"]) all.push_back(e);
    if (page["items"].empty()) return all;
    after = page["last_seq"];
  }
}

ApiClient control_client(LabFixture& lab) {
  Endpoint e;
  e.unix_socket = (lab.dir / "state" / "colorlabd.sock").string();
  return ApiClient(e);
}

}  // namespace

TEST(EventStream, ResumesAcrossAKilledDaemonWithNoEventLostOrRepeated) {
  LabFixture lab;
  auto api = control_client(lab);
  json e = api.post("/v1/executions", {{"campaign", "luminance-spot"}, {"params", {{"readings", 30}}}});

  auto first = read_stream(lab.url(), 3);
  ASSERT_FALSE(first.empty());
  ASSERT_EQ(first[0].event, "snapshot");
  json snapshot = json::parse(first[0].data);
  EXPECT_EQ(first[0].id, std::to_string(snapshot["last_seq"].get<std::int64_t>()));
  EXPECT_TRUE(snapshot.contains("executions") && snapshot.contains("instruments") && snapshot.contains("queue"));
  ASSERT_GT(first.size(), 1u) << "no event in 3 s of a running campaign";
  std::string last_id = first.back().id;

  lab.kill_daemon();
  lab.start_daemon();  // the execution resumes by itself
  auto restarted = control_client(lab);

  std::vector<SseEvent> received(first.begin() + 1, first.end());
  for (int round = 0; round < 40; ++round) {
    auto more = read_stream(lab.url(), 3, last_id);
    for (const auto& ev : more) {
      ASSERT_NE(ev.event, "snapshot") << "a resumed stream must not start over";
      received.push_back(ev);
    }
    if (!more.empty()) last_id = more.back().id;
    if (restarted.get("/v1/executions/" + e["id"].get<std::string>())["status"] == "finished_ok" &&
        last_id == std::to_string(event_log(restarted, 0).back()["seq"].get<std::int64_t>())) {
      break;
    }
  }
  auto truth = event_log(restarted, snapshot["last_seq"].get<std::int64_t>());
  ASSERT_EQ(received.size(), truth.size()) << "events lost or repeated";
  for (std::size_t i = 0; i < truth.size(); ++i) {
    EXPECT_EQ(received[i].id, std::to_string(truth[i]["seq"].get<std::int64_t>()));
    EXPECT_EQ(received[i].event, truth[i]["topic"]);
    EXPECT_EQ(json::parse(received[i].data)["payload"], truth[i]["payload"]);
  }
  bool finished = false;
  for (const auto& ev : received) finished |= json::parse(ev.data)["payload"].value("status", "") == "finished_ok";
  EXPECT_TRUE(finished) << "the stream never carried the run's end";
}

TEST(EventStream, MeasurementsComePagedAndFilteredAndTheRunDocumentStaysSmall) {
  LabFixture lab;
  auto api = control_client(lab);
  json e = api.post("/v1/executions", {{"campaign", "luminance-spot"}, {"params", {{"readings", 7}}}});
  for (int i = 0; i < 600; ++i) {
    if (api.get("/v1/executions/" + e["id"].get<std::string>())["status"] == "finished_ok") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  std::string run_id = e["run_id"];
  ApiClient reader(Endpoint::from_url(lab.url()));
  json run = reader.get("/v1/runs/" + run_id);
  EXPECT_FALSE(run.contains("measurements"));
  EXPECT_EQ(run["measurement_count"], 7);

  // Pages of 3 follow each other in seq order to the end, with no gap and no repeat.
  std::vector<std::int64_t> seqs;
  std::string target = "/v1/runs/" + run_id + "/measurements?limit=3";
  int pages = 0;
  for (;;) {
    json page = reader.get(target);
    ++pages;
    for (const auto& m : page["items"]) seqs.push_back(m["seq"]);
    if (page["next_cursor"].is_null()) break;
    target = page["links"]["next"];
  }
  EXPECT_EQ(pages, 3);
  ASSERT_EQ(seqs.size(), 7u);
  for (std::size_t i = 1; i < seqs.size(); ++i) EXPECT_GT(seqs[i], seqs[i - 1]);

  auto all = colorlab::client::fetch_measurements(reader, run_id);
  EXPECT_EQ(all.size(), 7u);
  EXPECT_EQ(colorlab::client::fetch_measurements(reader, run_id, "quantity=luminance").size(), 7u);
  EXPECT_EQ(colorlab::client::fetch_measurements(reader, run_id, "quantity=nothing").size(), 0u);
  EXPECT_EQ(colorlab::client::fetch_measurements(reader, run_id, "instrument=ls110").size(), 7u);
  std::string one_step = all[2]["step"];
  auto prefixed = colorlab::client::fetch_measurements(reader, run_id, "step_prefix=" + one_step);
  ASSERT_GE(prefixed.size(), 1u);
  for (const auto& m : prefixed) EXPECT_EQ(m["step"].get<std::string>().rfind(one_step, 0), 0u);

  auto bad = reader.request("GET", "/v1/runs/" + run_id + "/measurements?cursor=abc");
  EXPECT_EQ(bad.status, 400);
  EXPECT_EQ(reader.request("GET", "/v1/runs/no-such-run/measurements").status, 404);
}
