// The dry run against the simulated lab: its estimate of a campaign's duration, made from the
// timings this lab learned on *other* runs (a smaller grid in the other order, a chart of another
// size), is within the 20 % of what the run then takes; its checks name each limit a
// campaign would break, and it moves and stores nothing.
#include <chrono>
#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include <fstream>

#include "colorlab/client/api_client.hpp"
#include "colorlab/sim/control_channel.hpp"
#include "resume_support.hpp"

using namespace colorlab;
using namespace colorlab::testing;
using nlohmann::json;

namespace {

json dry_run(const client::ApiClient& api, const std::string& campaign, const json& params) {
  return api.post("/v1/executions", {{"campaign", campaign}, {"params", params}, {"dry_run", true}});
}

// Runs the campaign and returns its wall time in seconds.
double timed_run(const client::ApiClient& api, const std::string& campaign, const json& params) {
  const auto start = std::chrono::steady_clock::now();
  run_to_end(api, campaign, params, std::chrono::seconds(240));
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// What the simulated instruments have been asked to do so far (the simulator's own account).
json lab_truth(const DaemonProcess& daemon) {
  json endpoint = json::parse(std::ifstream(daemon.state_dir() / "colorlabd.endpoint"));
  json t = sim::send_control_command(endpoint.at("simulator_control").get<std::string>(), {{"cmd", "truth"}});
  return json{
      {"lamps_on", t["lamps_on"]},
      {"dimmer", t["dimmer"]},
      {"ls110_readings", t["ls110"]["readings_served"]},
      {"head_mm", t["spectrolino"]["head_mm"]},
      {"spectra", t["spectrolino"]["measurements"]},
  };
}

const json* problem_mentioning(const json& report, const std::string& text) {
  for (const auto& p : report["problems"]) {
    if (p["message"].get<std::string>().find(text) != std::string::npos) return &p;
  }
  return nullptr;
}

}  // namespace

TEST(DryRun, EstimateFromTimingsLearnedOnOtherRunsIsWithinTwentyPercentOfTheRun) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 200, 5));
  auto api = api_for(daemon);

  // A fresh lab has timed nothing: every figure is an assumption, and the report says so.
  json fresh = dry_run(api, "chart-read", {{"chart", "sg"}});
  EXPECT_TRUE(fresh["ok"].get<bool>()) << fresh.dump(2);
  EXPECT_EQ(fresh["estimate"]["measured_share"].get<double>(), 0.0);

  // What the lab learns from: a lamp-major grid of one row and a ColorChecker 24.
  const json learn_grid = {
      {"rows", 1},
      {"cols", 2},
      {"lamps", {"TL84", "D65"}},
      {"dimmer_levels", {100, 50}},
      {"order", "lamp-major"},
  };
  timed_run(api, "cabinet-grid", learn_grid);
  timed_run(api, "chart-read", {{"chart", "cc24"}});

  // What it estimates: the grid in the other order (a warm-up per spot instead of per lamp), with
  // more spots and levels, and the SG's 140 patches (three calibrations instead of one).
  const json grid = {
      {"rows", 2},
      {"cols", 3},
      {"lamps", {"TL84", "D65"}},
      {"dimmer_levels", {100, 50, 25}},
      {"order", "spot-major"},
  };
  const json sg = {{"chart", "sg"}};
  for (const auto& [campaign, params] : {std::pair{std::string("cabinet-grid"), grid}, std::pair{std::string("chart-read"), sg}}) {
    json report = dry_run(api, campaign, params);
    ASSERT_TRUE(report["ok"].get<bool>()) << report.dump(2);
    const json& e = report["estimate"];
    // Every kind of call the run makes was timed on the learning runs.
    EXPECT_GT(e["measured_share"].get<double>(), 0.99) << e.dump(2);
    const double estimate = e["wall_seconds"].get<double>();
    const double actual = timed_run(api, campaign, params);
    std::cout << "[dry run] " << campaign << ": estimated " << estimate << " s, took " << actual << " s ("
              << 100 * (estimate - actual) / actual << " %)\n";
    // The bound: the estimate within 20 % of the simulated run's duration.
    EXPECT_NEAR(estimate, actual, 0.2 * actual) << e.dump(2);
    if (campaign == "cabinet-grid") {
      // Spot-major: the first spot lights both lamps, every later spot one (its first lamp is the
      // previous spot's last).
      EXPECT_EQ(report["lamp_warmups"].get<int>(), 2 + 5);
      ASSERT_EQ(report["operator_actions"].size(), 1u);
      EXPECT_EQ(report["operator_actions"][0]["action"], "aim_meter");
      EXPECT_EQ(report["operator_actions"][0]["count"], 6);
      EXPECT_EQ(report["operator_actions"][0]["by"], "simulated lab");
    }
  }
}

TEST(DryRun, NamesEveryLimitACampaignWouldBreakAndMovesAndStoresNothing) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), 1000, 5));
  auto api = api_for(daemon);
  const json truth_before = lab_truth(daemon);

  // A lamp the cabinet does not have: reported, and the rest of the campaign is still checked.
  json lamps = dry_run(api, "cabinet-grid", {{"rows", 1}, {"cols", 1}, {"lamps", {"D65", "UV2"}}, {"dimmer_levels", {100}}});
  EXPECT_FALSE(lamps["ok"].get<bool>());
  EXPECT_TRUE(problem_mentioning(lamps, "'UV2' is not one of")) << lamps.dump(2);
  EXPECT_TRUE(lamps["finished"].get<bool>());

  // A chart placed beyond the SpectroScan T's 310 mm: the script's own plan refuses it, at its line.
  json off_table = dry_run(api, "chart-read", {{"chart", "sg"}, {"first_x_mm", 300}});
  EXPECT_FALSE(off_table["ok"].get<bool>());
  EXPECT_TRUE(problem_mentioning(off_table, "off the table")) << off_table.dump(2);
  EXPECT_GT(off_table["stopped_at"]["line"].get<int>(), 0);

  // A reference run that does not exist stops characterize-camera where the real run would stop.
  json no_ref = dry_run(api, "characterize-camera", {{"reference_run", "0190aaaa-0000-7000-8000-000000000000"}});
  EXPECT_FALSE(no_ref["ok"].get<bool>());
  EXPECT_FALSE(no_ref["finished"].get<bool>());

  // Parameters are checked as a start checks them: 400, not a report.
  try {
    dry_run(api, "cabinet-grid", {{"rows", 0}});
    ADD_FAILURE() << "rows = 0 was accepted";
  } catch (const client::ApiError& e) {
    EXPECT_EQ(e.problem().status, 400);
  }

  // Nothing was stored, nothing ran, no instrument was touched.
  EXPECT_TRUE(api.get("/v1/runs")["items"].empty());
  const auto events = api.get("/v1/events");  // held: a range-for over a temporary's member reads freed memory
  for (const auto& ev : events["items"]) EXPECT_NE(ev["topic"], "execution") << ev.dump();
  EXPECT_EQ(lab_truth(daemon), truth_before);
}
