// The wall clock stepped back and forward while colorlabd runs a queue (a lab PC's NTP jump), with
// Debian's libfaketime preloaded into the daemon and its simulated lab, the monotonic clock left alone
// (FAKETIME_DONT_FAKE_MONOTONIC): waits, timeouts, back-offs and learned timings run on the steady clock,
// so the jumps show only in the wall-clock timestamps the runs record. Issue 27.
#include <algorithm>
#include <ctime>
#include <fstream>
#include <map>
#include <thread>

#include <gtest/gtest.h>

#include "colorlab/sim/control_channel.hpp"
#include "resume_support.hpp"
#include "scoped_env.hpp"

using namespace colorlab;
using namespace colorlab::testing;
using nlohmann::json;

namespace {

constexpr double kTimeScale = 100;
constexpr int kReadings = 20;
constexpr double kIntervalS = 5;

std::string libfaketime() {
  for (const char* p : {"/usr/lib/x86_64-linux-gnu/faketime/libfaketimeMT.so.1", "/usr/lib/aarch64-linux-gnu/faketime/libfaketimeMT.so.1",
                        "/usr/lib/faketime/libfaketimeMT.so.1"}) {
    if (std::filesystem::exists(p)) return p;
  }
  return "";
}

// The clock as libfaketime reads it from the file on each call (FAKETIME_NO_CACHE): "+0", "-3h", "+2h".
void set_clock(const std::filesystem::path& file, const std::string& offset) {
  const auto tmp = file.string() + ".tmp";
  std::ofstream(tmp) << offset << "\n";
  std::filesystem::rename(tmp, file);
}

double unix_seconds(const std::string& iso) {  // "2026-11-22T00:01:48.123Z"
  std::tm tm{};
  double s = 0;
  if (std::sscanf(iso.c_str(), "%d-%d-%dT%d:%d:%lfZ", &tm.tm_year, &tm.tm_mon, &tm.tm_mday, &tm.tm_hour, &tm.tm_min, &s) != 6) {
    ADD_FAILURE() << "not an ISO 8601 UTC time: " << iso;
    return 0;
  }
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  return static_cast<double>(::timegm(&tm)) + s;
}

json run_of_execution(const client::ApiClient& api, const std::string& execution_id) {
  const json e = api.get("/v1/executions/" + execution_id);
  return client::fetch_run(api, e["run_id"].get<std::string>());
}

// The running queue item's execution id once its run has `n` measurements.
std::string wait_current_with(const client::ApiClient& api, std::size_t n, const std::string& not_this = "") {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    const json q = api.get("/v1/queue?history=300");
    if (q["current"].is_object() && q["current"]["execution_id"].is_string()) {
      const std::string id = q["current"]["execution_id"];
      if (id != not_this && run_of_execution(api, id)["measurements"].size() >= n) return id;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ADD_FAILURE() << "no queue item reached " << n << " measurements within 60 s";
  return "";
}

std::vector<json> execution_events(const client::ApiClient& api) {
  std::vector<json> out;
  std::int64_t after = 0;
  for (;;) {
    const json page = api.get("/v1/events?topic=execution&limit=300&after=" + std::to_string(after));
    if (page["items"].empty()) return out;
    for (const auto& ev : page["items"]) out.push_back(ev);
    after = page["items"].back()["seq"].get<std::int64_t>();
  }
}

TEST(ClockSteps, AQueueRunsThroughTheWallClockSteppingBackAndForward) {
  const std::string faketime = libfaketime();
  ASSERT_FALSE(faketime.empty()) << "libfaketime is not installed (Debian's faketime; scripts/setup.sh installs it)";
  TempDir dir;
  const auto clock_file = dir / "clock";
  set_clock(clock_file, "+0");
  const auto config = write_daemon_config(dir.path(), kTimeScale, 3);
  std::unique_ptr<DaemonProcess> daemon;
  {
    ScopedEnv env{{"LD_PRELOAD", faketime},
                  {"FAKETIME_TIMESTAMP_FILE", clock_file.string()},
                  {"FAKETIME_NO_CACHE", "1"},
                  {"FAKETIME_DONT_FAKE_MONOTONIC", "1"},
                  {"ASAN_OPTIONS", asan_options_for_preload()}};
    daemon = std::make_unique<DaemonProcess>(dir / "state", config);
  }
  auto api = api_for(*daemon);
  const json params{{"readings", kReadings}, {"interval_s", kIntervalS}};
  std::vector<std::string> items;
  for (int i = 0; i < 2; ++i) items.push_back(api.post("/v1/queue", {{"campaign", "luminance-spot"}, {"params", params}})["id"]);
  const auto started = std::chrono::steady_clock::now();
  api.post("/v1/queue/start", json::object());

  // Three hours back during the first run, five forward (two ahead of the true time) during the second.
  const std::string first = wait_current_with(api, 3);
  ASSERT_FALSE(first.empty());
  set_clock(clock_file, "-3h");
  const std::string second = wait_current_with(api, 3, first);
  ASSERT_FALSE(second.empty());
  set_clock(clock_file, "+2h");

  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(90);
  json q;
  while (std::chrono::steady_clock::now() < deadline) {
    q = api.get("/v1/queue?history=300");
    if (q["items"].empty() && q["current"].is_null()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_TRUE(q["items"].empty() && q["current"].is_null()) << "the queue did not finish within 90 s: " << q.dump(1);
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

  // Both runs complete: every step once, in order, each reading the simulator's truth within its noise.
  json endpoint = json::parse(std::ifstream(daemon->state_dir() / "colorlabd.endpoint"));
  const json truth = sim::send_control_command(endpoint.at("simulator_control").get<std::string>(), {{"cmd", "truth"}})["ls110"];
  const double l = truth["luminance"].get<double>(), sigma = truth["noise_sigma"].get<double>();
  std::map<std::string, json> runs;
  for (const auto& id : {first, second}) {
    const json e = api.get("/v1/executions/" + id);
    ASSERT_EQ(e["status"], "finished_ok") << e.dump(2);
    runs[id] = run_of_execution(api, id);
    const json& ms = runs[id]["measurements"];
    ASSERT_EQ(ms.size(), static_cast<std::size_t>(kReadings));
    for (int i = 0; i < kReadings; ++i) {
      EXPECT_EQ(ms[static_cast<std::size_t>(i)]["step"], "reading/" + std::to_string(i));
      EXPECT_NEAR(ms[static_cast<std::size_t>(i)]["value"].get<double>(), l, 4 * sigma + 0.01 * l);
    }
  }
  for (const auto& item : items) EXPECT_EQ(api.get("/v1/queue/" + item)["state"], "done");

  // The jumps did happen in the daemon: the recorded wall times step back in the first run (by about three
  // hours) and forward in the second (by about five).
  auto largest_step = [](const json& ms, int sign) {
    double largest = 0;
    for (std::size_t i = 1; i < ms.size(); ++i) {
      const double d = sign * (unix_seconds(ms[i]["measured_at"]) - unix_seconds(ms[i - 1]["measured_at"]));
      largest = std::max(largest, d);
    }
    return largest;
  };
  EXPECT_GT(largest_step(runs[first]["measurements"], -1), 2 * 3600.0) << "the first run's clock never went back";
  EXPECT_GT(largest_step(runs[second]["measurements"], +1), 4 * 3600.0) << "the second run's clock never jumped forward";

  // Event order is the log's sequence, not the clock: each execution's statuses go waiting → running →
  // finished_ok with nothing after it, and the second item's execution is created after the first ended.
  std::map<std::string, std::vector<std::string>> statuses;
  std::map<std::string, std::int64_t> created, ended;
  std::int64_t previous = 0;
  for (const auto& ev : execution_events(api)) {
    EXPECT_GT(ev["seq"].get<std::int64_t>(), previous);
    previous = ev["seq"];
    const auto& p = ev["payload"];
    if (p.value("status", "") == "waiting" && p.contains("id")) created[p["id"]] = ev["seq"];
    if (!p.contains("execution_id") || !p.contains("status")) continue;
    const std::string id = p["execution_id"], status = p["status"];
    statuses[id].push_back(status);
    if (status == "finished_ok") ended[id] = ev["seq"];
  }
  for (const auto& id : {first, second}) {
    ASSERT_FALSE(statuses[id].empty()) << id;
    EXPECT_EQ(statuses[id].back(), "finished_ok");
    EXPECT_EQ(std::count(statuses[id].begin(), statuses[id].end(), "finished_ok"), 1);
  }
  ASSERT_TRUE(created.count(second) && ended.count(first));
  EXPECT_GT(created[second], ended[first]) << "the second item started before the first ended";

  // Learned timings come from the steady clock: a dry run of the same campaign estimates each call at no
  // less than nothing and the whole run at no more than the queue took, however far the wall clock jumped.
  const json dry = api.post("/v1/executions", {{"campaign", "luminance-spot"}, {"params", params}, {"dry_run", true}});
  const json& estimate = dry["estimate"];
  ASSERT_TRUE(estimate.is_object()) << dry.dump(2);
  for (const auto& k : estimate["by_key"]) {
    EXPECT_GE(k["lab_seconds"].get<double>(), 0) << k.dump();
    if (k.value("source", "") == "measured") {
      EXPECT_LE(k["lab_seconds"].get<double>(), wall_s * kTimeScale) << "a learned timing jumped with the clock: " << k.dump();
    }
  }
  EXPECT_LE(estimate["wall_seconds"].get<double>(), wall_s) << estimate.dump(2);
  daemon->kill9();
  EXPECT_EQ(integrity_check(dir / "state"), "ok");
}

}  // namespace
