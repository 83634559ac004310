// The crash-loop guard (issue 27) in a real colorlabd on the simulated lab. A run whose restarts keep
// dying — here colorlabd is killed with SIGKILL each time the resumed run relights its lamp and waits for
// it to warm up, so no step can commit — is no instrument's failure and must not end the night: the guard
// suspends it with the category crash-loop and the cause, retries it by itself after a back-off that
// doubles up to its bound, and an operator may resume it earlier (API or `colorlab resume`); once left
// alone it completes with every reading exactly once. When the retries are spent the run ends with the
// crash-loop problem and its queue item's on_failure decides: continue lets the next item run. The
// operator hears of it through the configured command and webhook.
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "colorlab/sim/control_channel.hpp"
#include "resume_support.hpp"

using namespace colorlab;
using namespace colorlab::testing;
using nlohmann::json;

namespace {

constexpr double kTimeScale = 20;
constexpr int kReadings = 12;

// Lights TL84, waits for it, then readings. The simulated lab starts with D65 lit and warm, so each fresh
// simulator (it dies with colorlabd) has TL84 cold: a resume relights it and waits for its warm-up again.
const char* kLit = R"lua(
return {
  needs = { "lamps", "luminance_meter" },
  run = function(p)
    lab.lamps.select("TL84")
    lab.dimmer.set(100, { settle_s = 1 })
    lab.wait_stable({ window_s = 60 })
    for i = 1, 12 do
      local r = lab.meter.measure()
      lab.record("reading/" .. i, { quantity = "luminance", value = r.luminance, unit = r.unit, instrument = r.instrument })
      lab.wait(20)  -- 12 s of wall time for the twelve: a kill after the third lands mid-run on a loaded machine
    end
  end,
}
)lua";

struct GuardLab {
  TempDir dir;
  std::unique_ptr<DaemonProcess> daemon;
  explicit GuardLab(const std::string& campaigns_toml, const std::string& extra = {}) {
    auto config = write_daemon_config(dir.path(), kTimeScale, 3, "[campaigns]\n" + campaigns_toml + extra);
    write_campaign(dir.path(), "lit.lua", kLit);
    daemon = std::make_unique<DaemonProcess>(dir / "state", config, dir / "colorlabd.log");
  }
  client::ApiClient api() const { return api_for(*daemon); }
};

std::filesystem::path control_socket(const DaemonProcess& daemon) {
  json endpoint = json::parse(std::ifstream(daemon.state_dir() / "colorlabd.endpoint"));
  return endpoint.at("simulator_control").get<std::string>();
}

// Kills colorlabd while the resumed run's lamp warms up. A tube lights at 85 % of its output and approaches
// it with τ = 120 lab seconds (docs/simulator.md); the restore waits for a drift under 0.5 % over 60 s, which
// takes 2.7 τ (324 s). Seen below 97 % (before 1.6 τ, 193 s), the lamp has more than 130 lab seconds of warm-up
// left — 6.5 s of wall time at this time scale — before the restore can end and a step commit: the kill lands
// in the warm-up.
::testing::AssertionResult kill_during_warmup(DaemonProcess& daemon) {
  auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  const auto socket = control_socket(daemon);
  std::string last;
  while (std::chrono::steady_clock::now() < deadline) {
    try {
      json truth = sim::send_control_command(socket, {{"cmd", "truth"}});
      const json warmup = truth.value("warmup", json::object());  // held: items() of a temporary would dangle
      last = warmup.dump();
      for (const auto& [lamp, factor] : warmup.items()) {
        if (factor.get<double>() < 0.97) {
          daemon.kill9();
          return ::testing::AssertionSuccess();
        }
      }
    } catch (const std::exception& e) {
      last = e.what();  // the simulated lab is still starting
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return ::testing::AssertionFailure() << "no lamp was warming up within 120 s (last: " << last << ")";
}

// The execution's events (topic execution), oldest first.
std::vector<json> execution_events(const client::ApiClient& api, const std::string& id) {
  std::vector<json> out;
  std::int64_t after = 0;
  for (;;) {
    json page = api.get("/v1/events?topic=execution&limit=300&after=" + std::to_string(after));
    if (page["items"].empty()) return out;
    for (const auto& ev : page["items"]) {
      after = ev["seq"].get<std::int64_t>();
      if (ev["payload"].value("execution_id", "") == id) out.push_back(ev);
    }
  }
}

std::vector<json> crash_loop_suspensions(const client::ApiClient& api, const std::string& id) {
  std::vector<json> out;
  for (const auto& ev : execution_events(api, id)) {
    const auto& p = ev["payload"];
    if (p.value("status", "") == "suspended" && p.contains("suspension") && p["suspension"]["category"] == "crash-loop") {
      out.push_back(p);
    }
  }
  return out;
}

std::size_t measurements_of(const client::ApiClient& api, const json& execution) {
  return client::fetch_run(api, execution["run_id"].get<std::string>())["measurements"].size();
}

// Waits until the execution has committed `n` readings, kills colorlabd at that moment and starts it again.
void kill_mid_run(GuardLab& lab, const json& execution, std::size_t n) {
  auto api = lab.api();
  for (int i = 0; i < 2400 && measurements_of(api, execution) < n; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_GE(measurements_of(api, execution), n) << "the campaign did not get going";
  lab.daemon->kill9();
  lab.daemon->start();
}

// Kills colorlabd during each resumed run's warm-up, starting it again each time, until the guard has
// suspended the execution `rounds` times (at most 4 kills per round: a kill that came after a commit,
// which the margin above rules out, would only cost another one).
void crash_until_suspended(GuardLab& lab, const std::string& id, std::size_t rounds) {
  for (int kills = 0; kills < 4 * static_cast<int>(rounds) + 4; ++kills) {
    if (crash_loop_suspensions(lab.api(), id).size() >= rounds) return;
    ASSERT_TRUE(kill_during_warmup(*lab.daemon));
    lab.daemon->start();
  }
  ASSERT_GE(crash_loop_suspensions(lab.api(), id).size(), rounds) << "the guard never tripped";
}

// Every reading once, in order: nothing lost, nothing doubled across the kills.
void expect_every_reading_once(const client::ApiClient& api, const json& execution) {
  json run = client::fetch_run(api, execution["run_id"].get<std::string>());
  ASSERT_EQ(run["measurements"].size(), static_cast<std::size_t>(kReadings)) << run["measurements"].dump();
  for (int i = 0; i < kReadings; ++i) {
    EXPECT_EQ(run["measurements"][static_cast<std::size_t>(i)]["step"], "reading/" + std::to_string(i + 1));
  }
}

// One HTTP POST's body, received by a listener on 127.0.0.1 (a webhook's receiver).
class WebhookReceiver {
 public:
  WebhookReceiver() {
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 || ::listen(fd_, 8) != 0) throw std::runtime_error("listen");
    socklen_t len = sizeof a;
    ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len);
    port_ = ntohs(a.sin_port);
    thread_ = std::thread([this] { serve(); });
  }
  ~WebhookReceiver() {
    stop_ = true;
    ::shutdown(fd_, SHUT_RDWR);
    ::close(fd_);
    thread_.join();
  }
  std::string url() const { return "http://127.0.0.1:" + std::to_string(port_) + "/hooks/secret-token"; }
  // The bodies received so far, each with the request line.
  std::vector<std::pair<std::string, json>> received() {
    std::lock_guard lock(mutex_);
    return bodies_;
  }

 private:
  void serve() {
    while (!stop_) {
      int c = ::accept4(fd_, nullptr, nullptr, SOCK_CLOEXEC);
      if (c < 0) return;
      timeval tv{10, 0};
      ::setsockopt(c, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
      std::string data;
      char buf[4096];
      std::size_t want = std::string::npos;
      for (;;) {
        ssize_t n = ::recv(c, buf, sizeof buf, 0);
        if (n <= 0) break;
        data.append(buf, static_cast<std::size_t>(n));
        auto end = data.find("\r\n\r\n");
        if (end != std::string::npos && want == std::string::npos) {
          std::string head = data.substr(0, end);
          for (auto& ch : head) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
          auto at = head.find("content-length:");
          want = end + 4 + (at == std::string::npos ? 0 : std::stoul(head.substr(at + 15)));
        }
        if (want != std::string::npos && data.size() >= want) break;
      }
      const std::string reply = "HTTP/1.1 204 No Content\r\nConnection: close\r\n\r\n";
      ::send(c, reply.data(), reply.size(), MSG_NOSIGNAL);
      ::close(c);
      auto end = data.find("\r\n\r\n");
      if (end == std::string::npos) continue;
      std::lock_guard lock(mutex_);
      bodies_.emplace_back(data.substr(0, data.find("\r\n")), json::parse(data.substr(end + 4), nullptr, false));
    }
  }
  int fd_ = -1;
  unsigned short port_ = 0;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  std::mutex mutex_;
  std::vector<std::pair<std::string, json>> bodies_;
};

// [notify] whose command appends COLORLAB_EVENT to `file`.events, then the notification (its stdin) to `file`,
// one a line: once a document is in `file`, its event is in the other.
std::string notify_toml(const std::filesystem::path& file, const std::string& webhook) {
  return "[notify]\ncommand = [\"/bin/sh\", \"-c\", \"echo \\\"$COLORLAB_EVENT\\\" >> \\\"$1.events\\\"; { cat; echo; } >> \\\"$1\\\"\", "
         "\"notify\", \"" +
         file.string() + "\"]\nwebhook = \"" + webhook + "\"\ntimeout_s = 10\n";
}

std::vector<json> notifications(const std::filesystem::path& file) {
  std::vector<json> out;
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) out.push_back(json::parse(line, nullptr, false));
  }
  return out;
}

template <typename Pred>
bool eventually(Pred done, std::chrono::seconds timeout = std::chrono::seconds(30)) {
  auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return done();
}

}  // namespace

// Left alone, the guard retries by itself: each suspension's back-off doubles (0.25 s, 0.5 s, then the
// 0.75 s bound), each ends in a retry by the back-off, and the run then completes whole.
TEST(CrashLoopGuard, SuspendsBacksOffRetriesByItselfAndTheRunCompletes) {
  GuardLab lab("max_resume_attempts = 1\ncrash_loop_backoff_s = 0.25\ncrash_loop_backoff_max_s = 0.75\ncrash_loop_retries = 4\n");
  auto api = lab.api();
  auto e = api.post("/v1/executions", {{"campaign", "lit"}, {"params", json::object()}});
  std::string id = e["id"];
  kill_mid_run(lab, e, 3);
  crash_until_suspended(lab, id, 3);
  auto done = wait_terminal(lab.api(), id, std::chrono::seconds(180));
  ASSERT_EQ(done["status"], "finished_ok") << done.dump(2);
  EXPECT_FALSE(done.contains("suspension")) << "a finished run waits for nothing";
  expect_every_reading_once(lab.api(), e);

  // The schedule, in the order it happened: suspended (crash-loop, retry k, its back-off), then running
  // again, retried by the back-off — never a terminal state in between.
  std::vector<json> steps;
  for (const auto& ev : execution_events(lab.api(), id)) {
    const auto& p = ev["payload"];
    if (p.value("status", "") == "suspended" && p.contains("suspension") && p["suspension"]["category"] == "crash-loop") {
      steps.push_back({
          {"suspended", p["suspension"]["retry"]},
          {"backoff_s", p["suspension"]["backoff_s"]},
          {"retry_at", p["suspension"]["retry_at"]},
          {"reason", p["reason"]},
      });
    } else if (p.contains("resumed_by")) {
      steps.push_back({{"retried_by", p["resumed_by"]["by"]}, {"retry", p["resumed_by"]["retry"]}});
    } else if (p.value("status", "") == "finished_error" || p.value("status", "") == "aborted") {
      ADD_FAILURE() << "ended on the way: " << p.dump();
    }
  }
  ASSERT_EQ(steps.size(), 6u) << json(steps).dump(1);
  const double backoffs[] = {0.25, 0.5, 0.75};
  for (int k = 0; k < 3; ++k) {
    const auto& s = steps[static_cast<std::size_t>(2 * k)];
    EXPECT_EQ(s["suspended"], k + 1) << json(steps).dump(1);
    EXPECT_DOUBLE_EQ(s["backoff_s"].get<double>(), backoffs[k]);
    EXPECT_TRUE(s["retry_at"].is_string()) << s;
    EXPECT_NE(s["reason"].get<std::string>().find("crash loop: colorlabd stopped"), std::string::npos) << s;
    const auto& r = steps[static_cast<std::size_t>(2 * k + 1)];
    EXPECT_EQ(r["retried_by"], "back-off") << json(steps).dump(1);
    EXPECT_EQ(r["retry"], k + 1);
  }
  lab.daemon->kill9();
  EXPECT_EQ(integrity_check(lab.dir / "state"), "ok");
}

// With a long back-off the suspension stays: the execution JSON carries the category and the cause (no
// instrument error), the operator resumes it with `colorlab resume`, and it completes. The configured
// command and webhook heard of the crash loop.
TEST(CrashLoopGuard, ASuspensionShowsItsCauseAndTheOperatorResumesItWithTheCli) {
  WebhookReceiver hook;
  TempDir out;
  const auto file = out / "notifications.jsonl";
  GuardLab lab("max_resume_attempts = 1\ncrash_loop_backoff_s = 3600\ncrash_loop_backoff_max_s = 3600\ncrash_loop_retries = 2\n",
               notify_toml(file, hook.url()));
  auto api = lab.api();
  auto e = api.post("/v1/executions", {{"campaign", "lit"}, {"params", json::object()}});
  std::string id = e["id"];
  kill_mid_run(lab, e, 3);
  crash_until_suspended(lab, id, 1);

  api = lab.api();
  json s = api.get("/v1/executions/" + id);
  ASSERT_EQ(s["status"], "suspended") << s.dump(2);
  ASSERT_TRUE(s.contains("suspension")) << s.dump(2);
  const json& why = s["suspension"];
  EXPECT_EQ(why["category"], "crash-loop");
  EXPECT_EQ(why["problem"]["code"], "crash-loop");
  EXPECT_EQ(why["problem"]["title"], "Crash loop") << "not an instrument error";
  EXPECT_NE(why["problem"]["hint"].get<std::string>().find("colorlab resume"), std::string::npos) << why.dump();
  EXPECT_EQ(why["retry"], 1);
  EXPECT_EQ(why["retries"], 2);
  EXPECT_EQ(why["backoff_s"], 3600);
  EXPECT_EQ(why["restarts"], 2);
  EXPECT_TRUE(why.contains("retry_at"));
  EXPECT_FALSE(s.contains("error")) << "a suspension is no failure";
  EXPECT_NE(s["reason"].get<std::string>().find("crash loop"), std::string::npos) << s.dump(2);

  // The operator heard of the crash loop, by command and by webhook, with the same document (asked before
  // colorlabd stops: a notification still queued then is dropped).
  ASSERT_TRUE(eventually([&] { return !notifications(file).empty() && !hook.received().empty(); }))
      << "no notification arrived";
  json n = notifications(file).front();
  EXPECT_EQ(n["event"], "crash-loop") << n.dump(2);
  EXPECT_EQ(n["execution_id"], id);
  EXPECT_EQ(n["campaign"], "lit");
  EXPECT_EQ(n["category"], "crash-loop");
  EXPECT_EQ(n["status"], "suspended");
  EXPECT_EQ(n["suspension"]["retry_at"], why["retry_at"]);
  EXPECT_TRUE(n.contains("time") && n.contains("host"));
  std::ifstream events(file.string() + ".events");
  std::string first_event;
  std::getline(events, first_event);
  EXPECT_EQ(first_event, "crash-loop") << "COLORLAB_EVENT names the event";
  auto [request_line, posted] = hook.received().front();
  EXPECT_EQ(request_line, "POST /hooks/secret-token HTTP/1.1");
  EXPECT_EQ(posted["event"], "crash-loop");
  EXPECT_EQ(posted["execution_id"], id);
  // Still suspended after a restart during the back-off: it neither resumes at once nor counts an attempt.
  EXPECT_EQ(lab.daemon->terminate(), 0);
  lab.daemon->start();
  api = lab.api();
  json again = api.get("/v1/executions/" + id);
  EXPECT_EQ(again["status"], "suspended") << again.dump(2);
  EXPECT_EQ(again["suspension"]["retry_at"], why["retry_at"]);
  EXPECT_EQ(again["resume_attempts"], s["resume_attempts"]);

  auto cli = run_command({bin_path("colorlab"), "--socket", lab.daemon->unix_socket(), "resume", id});
  EXPECT_EQ(cli.exit_code, 0) << cli.out << cli.err;
  auto done = wait_terminal(api, id, std::chrono::seconds(180));
  ASSERT_EQ(done["status"], "finished_ok") << done.dump(2);
  expect_every_reading_once(api, e);
  bool by_client = false;
  for (const auto& ev : execution_events(api, id)) {
    const auto& p = ev["payload"];
    by_client = by_client || (p.contains("resumed_by") && p["resumed_by"].value("by", "") == "a client");
  }
  EXPECT_TRUE(by_client) << "the resume is recorded as the operator's";

  lab.daemon->kill9();
}

std::string log_of(const GuardLab& lab) {
  std::ifstream log(lab.dir / "colorlabd.log");
  std::stringstream text;
  text << log.rdbuf();
  return text.str();
}

// A failed run notifies too; a webhook nobody answers is logged — by its origin only, its path being its
// secret — and holds neither the run nor the daemon.
TEST(CrashLoopGuard, AFailedRunNotifiesAndAnUnreachableWebhookHoldsNothing) {
  TempDir out;
  const auto file = out / "notifications.jsonl";
  // Port 9 (discard) on loopback: nothing listens there in a test machine; the POST fails at once.
  GuardLab lab("", notify_toml(file, "http://127.0.0.1:9/hooks/secret-token"));
  write_campaign(lab.dir.path(), "dirty.lua", R"lua(
return {
  needs = { "luminance_meter" },
  run = function(p)
    local r = lab.meter.measure()
    lab.record("before", { quantity = "luminance", value = r.luminance, unit = r.unit, instrument = r.instrument })
    error("the tile is dirty")
  end,
}
)lua");
  auto api = lab.api();
  auto e = api.post("/v1/executions", {{"campaign", "dirty"}, {"params", json::object()}});
  auto done = wait_terminal(api, e["id"]);
  ASSERT_EQ(done["status"], "finished_error") << done.dump(2);
  ASSERT_TRUE(eventually([&] { return !notifications(file).empty(); })) << "no notification for the failed run";
  json n = notifications(file).front();
  EXPECT_EQ(n["event"], "failed");
  EXPECT_EQ(n["execution_id"], e["id"]);
  EXPECT_EQ(n["status"], "finished_error");
  EXPECT_NE(n["reason"].get<std::string>().find("the tile is dirty"), std::string::npos) << n.dump(2);
  EXPECT_EQ(n["problem"]["code"], "script_error");
  // The failed webhook was logged, and the daemon serves and runs the next campaign as ever.
  EXPECT_TRUE(eventually([&] { return log_of(lab).find("POST to http://127.0.0.1:9 failed") != std::string::npos; }))
      << "the failed POST is not in the log";
  auto next = run_to_end(api, "luminance-spot", {{"readings", 2}});
  EXPECT_EQ(next["measurements"].size(), 2u);
  lab.daemon->kill9();
  EXPECT_EQ(log_of(lab).find("secret-token"), std::string::npos) << "the webhook's secret path reached the log";
}

// The bound runs out: the run ends with the crash-loop problem, and its queue item's on_failure = continue
// lets the next item run — one sick campaign does not hold the rest of the night.
TEST(CrashLoopGuard, WhenTheRetriesAreSpentTheQueueGoesOnWithTheNextItem) {
  GuardLab lab("max_resume_attempts = 1\ncrash_loop_backoff_s = 0.25\ncrash_loop_backoff_max_s = 0.25\ncrash_loop_retries = 1\n");
  auto api = lab.api();
  json sick = api.post("/v1/queue", {{"campaign", "lit"}, {"params", json::object()}, {"on_failure", "continue"}});
  json next = api.post("/v1/queue", {{"campaign", "luminance-spot"}, {"params", {{"readings", 3}}}, {"on_failure", "continue"}});
  api.post("/v1/queue/start", json::object());
  std::string id;
  ASSERT_TRUE(eventually([&] {
    json q = lab.api().get("/v1/queue");
    if (q["current"].is_object() && q["current"].contains("execution_id")) id = q["current"]["execution_id"];
    return !id.empty();
  })) << "the first item never started";
  kill_mid_run(lab, lab.api().get("/v1/executions/" + id), 3);
  // Suspended once and retried by the back-off; the retry dies too: no retries left.
  crash_until_suspended(lab, id, 1);
  for (int kills = 0; kills < 6; ++kills) {
    if (lab.api().get("/v1/executions/" + id)["status"] == "finished_error") break;
    ASSERT_TRUE(kill_during_warmup(*lab.daemon));
    lab.daemon->start();
  }
  api = lab.api();
  json ended = api.get("/v1/executions/" + id);
  ASSERT_EQ(ended["status"], "finished_error") << ended.dump(2);
  EXPECT_EQ(ended["error"]["code"], "crash-loop") << ended.dump(2);
  EXPECT_EQ(ended["error"]["title"], "Crash loop");
  EXPECT_NE(ended["reason"].get<std::string>().find("also after 1 retry"), std::string::npos) << ended.dump(2);
  // What it measured before stays, each reading once.
  json run = client::fetch_run(api, ended["run_id"].get<std::string>());
  std::set<std::string> steps;
  for (const auto& m : run["measurements"]) EXPECT_TRUE(steps.insert(m["step"].get<std::string>()).second) << m["step"];
  EXPECT_GE(steps.size(), 3u);

  json q;
  ASSERT_TRUE(eventually([&] {
    q = api.get("/v1/queue?history=10");
    return q["items"].empty();
  },
                         std::chrono::seconds(120)))
      << q.dump(1);
  EXPECT_FALSE(q["halted"].get<bool>()) << q.dump(1);
  std::map<std::string, json> history;
  for (const auto& item : q["history"]) history[item["id"]] = item;
  EXPECT_EQ(history[sick["id"]]["state"], "failed") << q.dump(1);
  EXPECT_NE(history[sick["id"]]["reason"].get<std::string>().find("times in a row"), std::string::npos) << q.dump(1);
  EXPECT_EQ(history[next["id"]]["state"], "done") << q.dump(1);
  lab.daemon->kill9();
}
