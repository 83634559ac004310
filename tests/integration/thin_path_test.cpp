// The thin path through every layer, with real processes: colorlab-sim serves an LS-110 on a
// pty, colorlabd drives it over the serial line, stores readings in SQLite and serves them over
// HTTP, and the colorlab CLI reads them back. Truth is the simulator's scene value.
#include <cmath>
#include <fstream>
#include <set>
#include <thread>

#include <gtest/gtest.h>

#include "colorlab/client/api_client.hpp"
#include "colorlab/testing/process.hpp"
#include "lab_fixture.hpp"

using colorlab::testing::LabFixture;
using colorlab::testing::Process;
using nlohmann::json;

namespace {

std::string trim(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  return s;
}

}  // namespace

TEST(ThinPath, StoredLuminanceEqualsTheScenesValueWithinNoise) {
  LabFixture lab;
  auto r = lab.cli({"run", "luminance-spot", "--id-only", "--param", "readings=5"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::string run_id = trim(r.out);

  json truth = lab.sim_control({{"cmd", "truth"}})["ls110"];
  double expected = truth["luminance"], sigma = truth["noise_sigma"];
  ASSERT_GT(expected, 100.0);  // D65 at 100 %: the cabinet floor is 170–320 cd/m²

  json run = lab.cli_json({"show", run_id});
  EXPECT_EQ(run["status"], "finished_ok");
  EXPECT_TRUE(run["simulated"]) << "simulated data must never pass for a measurement";
  ASSERT_EQ(run["measurements"].size(), 5u);
  double sum = 0;
  for (const auto& m : run["measurements"]) {
    EXPECT_TRUE(m["simulated"]);
    EXPECT_EQ(m["quantity"], "luminance");
    EXPECT_EQ(m["unit"], "cd/m2");
    double v = m["value"];
    EXPECT_NEAR(v, expected, 5 * sigma + 0.01);  // the meter reports 2 decimals
    sum += v;
  }
  EXPECT_NEAR(sum / 5, expected, 5 * sigma / std::sqrt(5.0) + 0.01);
  EXPECT_NEAR(run["summary"]["script"]["mean"].get<double>(), sum / 5, 1e-9);
  EXPECT_NEAR(run["summary"]["measurements"]["luminance"]["mean"].get<double>(), sum / 5, 1e-9);

  // The same run through the list and the Unix socket.
  json runs = lab.cli_json({"runs"});
  ASSERT_FALSE(runs["items"].empty());
  EXPECT_EQ(runs["items"][0]["id"], run_id);
  auto via_socket = colorlab::testing::run_command(
      {colorlab::testing::bin_path("colorlab"), "--socket", (lab.dir / "state" / "colorlabd.sock").string(), "--json",
       "show", run_id});
  ASSERT_EQ(via_socket.exit_code, 0) << via_socket.err;
  EXPECT_EQ(json::parse(via_socket.out)["measurements"], run["measurements"]);
}

TEST(ThinPath, MeterOverRangeBecomesATypedErrorWithAHint) {
  LabFixture lab;
  lab.sim_control({{"cmd", "fault"}, {"instrument", "ls110"}, {"faults", {{"error_code", "ER10"}}}});
  auto r = lab.cli({"--json", "run", "luminance-spot"});
  EXPECT_EQ(r.exit_code, 3) << r.out << r.err;
  json run = json::parse(r.out);
  EXPECT_EQ(run["status"], "finished_error");
  EXPECT_EQ(run["error"]["code"], "misread");
  EXPECT_EQ(run["error"]["device_code"], "ER10");
  EXPECT_NE(run["error"]["detail"].get<std::string>().find("measuring range over"), std::string::npos);
  EXPECT_FALSE(run["error"]["hint"].get<std::string>().empty());
  EXPECT_TRUE(run["measurements"].empty());

  // The fault cleared, the same daemon measures again.
  lab.sim_control({{"cmd", "fault"}, {"instrument", "ls110"}, {"faults", json::object()}});
  EXPECT_EQ(lab.cli({"run", "luminance-spot"}).exit_code, 0);
}

// A silent meter is a condition an unattended night waits out (docs/campaigns.md, "suspend, not
// fail"): the run is suspended within the driver's timeouts with the typed reason and the operator's
// hint, the instrument shows what it needs — never a hang, never a silently stuck "running".
TEST(ThinPath, SilentMeterSuspendsTheRunWithTheOperatorsHintAndNeverHangs) {
  LabFixture lab(20, "{ reply_timeout_ms = 300, attempts = 2 }");
  lab.sim_control({{"cmd", "fault"}, {"instrument", "ls110"}, {"faults", {{"silent", true}}}});
  auto start = std::chrono::steady_clock::now();
  json execution = lab.cli_json({"run", "--detach", "luminance-spot"});
  colorlab::client::ApiClient api(colorlab::client::Endpoint::from_url(lab.url()));
  json e;
  while (std::chrono::steady_clock::now() - start < std::chrono::seconds(30)) {
    e = api.get("/v1/executions/" + execution["id"].get<std::string>());
    if (e["status"] == "suspended") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  auto took = std::chrono::steady_clock::now() - start;
  ASSERT_EQ(e["status"], "suspended") << e.dump(2);
  EXPECT_LT(took, std::chrono::seconds(20)) << "a silent meter must be reported, not hang the run";
  EXPECT_EQ(e["reason"].get<std::string>().rfind("instrument: ", 0), 0u) << e.dump();
  json problem, log;
  for (int i = 0; i < 50 && problem.is_null(); ++i) {
    log = api.get("/v1/events?topic=execution&limit=300");
    for (const auto& ev : log["items"]) {
      if (ev["payload"].value("suspended", false)) problem = ev["payload"]["problem"];
    }
    if (problem.is_null()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_EQ(problem["code"], "needs_operator") << log.dump();
  EXPECT_NE(problem.value("hint", std::string()).find("holding F"), std::string::npos) << problem.dump();
  json instruments = lab.cli_json({"instruments"});
  EXPECT_NE(instruments["items"][0]["state"], "ready");
  EXPECT_TRUE(instruments["items"][0].contains("problem"));
}

TEST(ThinPath, KillNineMidCampaignResumesByItselfWithNothingLostOrRepeated) {
  LabFixture lab(1);  // real time: each reading takes ~0.45 s, so the kill lands mid-campaign
  auto r = lab.cli({"run", "luminance-spot", "--detach", "--id-only", "--param", "readings=12"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::string run_id = trim(r.out);
  json run;
  for (int i = 0; i < 100; ++i) {
    run = lab.cli_json({"show", run_id});
    if (run["measurements"].size() >= 3) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_GE(run["measurements"].size(), 3u);
  lab.kill_daemon();

  // No new request: the restarted daemon resumes the execution from its last committed step.
  lab.start_daemon();
  json after;
  for (int i = 0; i < 300; ++i) {
    after = lab.cli_json({"show", run_id});
    if (after["status"] == "finished_ok" || after["status"] == "finished_error") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_EQ(after["status"], "finished_ok") << after.dump();
  ASSERT_EQ(after["measurements"].size(), 12u);
  std::set<std::string> steps;
  for (const auto& m : after["measurements"]) {
    EXPECT_TRUE(steps.insert(m["step"].get<std::string>()).second) << "a step was stored twice";
  }
  for (int i = 0; i < 12; ++i) EXPECT_TRUE(steps.count("reading/" + std::to_string(i))) << "reading/" << i << " missing";
  for (std::size_t i = 0; i < run["measurements"].size(); ++i) {
    EXPECT_EQ(after["measurements"][i]["value"], run["measurements"][i]["value"]);
  }
  // The summary is computed from the stored rows, so it counts the readings of both processes.
  EXPECT_EQ(after["summary"]["measurements"]["luminance"]["count"], 12);
}
