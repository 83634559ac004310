// kill -9 of colorlabd (and its embedded simulated lab with it) at random moments of the script
// campaigns, over 20 seeds. After each restart: the database passes integrity_check, the
// execution completes by itself with no new request, its stored steps are exactly those of an
// uninterrupted run (no gap, no duplicate, in order), and its readings agree with the
// uninterrupted run's within the simulator's noise.
#include <cmath>
#include <random>
#include <thread>

#include <gtest/gtest.h>

#include "resume_support.hpp"

using namespace colorlab::testing;
using nlohmann::json;

namespace {

constexpr double kTimeScale = 4;
constexpr int kReadings = 12;

struct Reference {
  std::vector<std::string> steps;
  std::vector<double> values;
  double mean = 0, stdev = 0;
};

// One uninterrupted run: the truth the interrupted ones are held to.
Reference reference_run(const std::string& campaign, const json& params, std::uint64_t seed) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), kTimeScale, seed));
  auto api = api_for(daemon);
  auto e = api.post("/v1/executions", {{"campaign", campaign}, {"params", params}});
  auto done = wait_terminal(api, e["id"]);
  EXPECT_EQ(done["status"], "finished_ok") << done.dump();
  json run = colorlab::client::fetch_run(api, e["run_id"].get<std::string>());
  Reference r;
  for (const auto& m : run["measurements"]) {
    r.steps.push_back(m["step"]);
    r.values.push_back(m["value"].get<double>());
  }
  double sum = 0, sq = 0;
  for (double v : r.values) sum += v;
  r.mean = sum / r.values.size();
  for (double v : r.values) sq += (v - r.mean) * (v - r.mean);
  r.stdev = r.values.size() > 1 ? std::sqrt(sq / (r.values.size() - 1)) : 0;
  return r;
}

// The lab is the same (simulator seed 1) in every run; `seed` draws when, and how often, to kill.
json interrupted_run(const std::string& campaign, const json& params, std::uint64_t seed, int max_delay_ms,
                     int& kills_done) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_daemon_config(dir.path(), kTimeScale, 1));
  auto api = api_for(daemon);
  auto e = api.post("/v1/executions", {{"campaign", campaign}, {"params", params}});
  std::mt19937 rng(static_cast<unsigned>(seed * 7919));
  int kills = 1 + static_cast<int>(seed % 2);
  for (int k = 0; k < kills; ++k) {
    std::this_thread::sleep_for(std::chrono::milliseconds(std::uniform_int_distribution<int>(30, max_delay_ms)(rng)));
    auto before = api.get("/v1/executions/" + e["id"].get<std::string>());
    if (before["status"] != "running" && before["status"] != "waiting") break;  // finished before the kill
    daemon.kill9();
    ++kills_done;
    EXPECT_EQ(integrity_check(daemon.state_dir()), "ok");
    daemon.start();
    api = api_for(daemon);
  }
  auto done = wait_terminal(api, e["id"]);
  EXPECT_EQ(done["status"], "finished_ok") << done.dump();
  EXPECT_EQ(done["resume_attempts"], 0);  // reset by the steps committed after the resume
  json run = colorlab::client::fetch_run(api, e["run_id"].get<std::string>());
  daemon.kill9();
  EXPECT_EQ(integrity_check(daemon.state_dir()), "ok");
  return run;
}

std::vector<std::string> steps_of(const json& run) {
  std::vector<std::string> out;
  for (const auto& m : run["measurements"]) out.push_back(m["step"]);
  return out;
}

}  // namespace

class KillNineLuminanceSpot : public ::testing::TestWithParam<int> {
 protected:
  static void SetUpTestSuite() { reference_ = new Reference(reference_run("luminance-spot", {{"readings", kReadings}}, 1)); }
  static void TearDownTestSuite() { delete reference_; }
  static Reference* reference_;
};
Reference* KillNineLuminanceSpot::reference_ = nullptr;

TEST_P(KillNineLuminanceSpot, ResumesByItselfWithTheUninterruptedRunsSteps) {
  const auto seed = static_cast<std::uint64_t>(GetParam());
  int kills = 0;
  json run = interrupted_run("luminance-spot", {{"readings", kReadings}}, seed, 1000, kills);
  EXPECT_GE(kills, 1) << "the kill must land mid-campaign";
  EXPECT_EQ(steps_of(run), reference_->steps);
  // Within the simulator's noise of the uninterrupted run (6 of its standard deviations).
  double tolerance = 6 * std::max(reference_->stdev, 0.05);
  for (const auto& m : run["measurements"]) {
    EXPECT_NEAR(m["value"].get<double>(), reference_->mean, tolerance) << m["step"];
    EXPECT_TRUE(m["simulated"]);
  }
  EXPECT_EQ(run["summary"]["measurements"]["luminance"]["count"], kReadings);
  EXPECT_EQ(run["summary"]["script"]["readings"], kReadings);
}

INSTANTIATE_TEST_SUITE_P(Seeds, KillNineLuminanceSpot, ::testing::Range(1, 15));
