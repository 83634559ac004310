// CPU priority of colorlabd's heavy work (issue 27, docs/configuration.md "CPU priority"): the threads and
// the processes it starts run at the nice value configured, as the kernel reports it in /proc (field 19 of
// stat). No timing here: only what the kernel says each thread's nice value is.
//
// Each expectation is min(19, the creator's nice + steps): run under `nice -n 19` a lowered thread cannot go
// lower, so the check then only says that nothing failed; at nice 0 (CI) it checks the steps.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <future>
#include <thread>

#include <boost/asio/io_context.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/core/thread_priority.hpp"
#include "colorlab/daemon/config.hpp"
#include "colorlab/daemon/embedded_sim.hpp"
#include "colorlab/daemon/report_service.hpp"
#include "colorlab/daemon/worker_pool.hpp"
#include "colorlab/testing/temp_dir.hpp"
#include "run_until.hpp"

namespace colorlab::daemon {
namespace {

namespace asio = boost::asio;
using nlohmann::json;
using testing::run_until;
using testing::TempDir;

int lowered(int steps) { return std::min(19, core::thread_nice() + steps); }

std::string thread_name() {
  std::ifstream in("/proc/thread-self/comm");
  std::string name;
  std::getline(in, name);
  return name;
}

TEST(ThreadPriority, WorkerPoolThreadsRunAtTheConfiguredNiceAndTheCommitterAsTheDaemon) {
  asio::io_context io;
  for (const auto& [nice, name] : {std::pair{3, std::string("workers")}, std::pair{0, std::string("committer")}}) {
    WorkerPoolOptions o;
    o.threads = 2;
    o.nice = nice;
    o.name = name;
    const int expected = lowered(nice);
    WorkerPool pool(io.get_executor(), o);
    int seen = -100;
    std::string seen_name;
    bool done = false;
    pool.submit(
        "a probe", [&] {
          seen = core::thread_nice();
          seen_name = thread_name();
          return json(); },
        [&](std::exception_ptr, json) { done = true; });
    const auto finished = [&] { return done; };
    ASSERT_NO_FATAL_FAILURE(run_until(io, finished, "the job"));
    EXPECT_EQ(seen, expected) << name;
    EXPECT_EQ(seen_name, name);
  }
}

TEST(ThreadPriority, AHeavyThreadLowersItselfAndWhatItStartsInherits) {
  core::set_heavy_thread_nice(4);
  const int expected = lowered(4);
  int mine = -100, child = -100, heavy_child = -100;
  std::string name;
  std::thread([&] {
    core::become_heavy_thread("heavy-test-thread-name");
    mine = core::thread_nice();
    name = thread_name();
    std::thread([&] { child = core::thread_nice(); }).join();
    // A heavy thread started by a heavy thread (a camera's decode thread rebuilt on its device thread) stays at
    // the process's nice + steps: the steps do not add up.
    std::thread([&] {
      core::become_heavy_thread("heavy-inner");
      heavy_child = core::thread_nice();
    }).join();
  }).join();
  core::set_heavy_thread_nice(0);
  EXPECT_EQ(mine, expected);
  EXPECT_EQ(child, expected);
  EXPECT_EQ(heavy_child, expected);
  EXPECT_EQ(name, "heavy-test-thre");  // the kernel keeps 15 characters
  // 0 leaves a thread as it was (main's behaviour before issue 27).
  int same = -100;
  const int now = core::thread_nice();
  std::thread([&] {
    core::become_heavy_thread("heavy-test");
    same = core::thread_nice();
  }).join();
  EXPECT_EQ(same, now);
}

TEST(ThreadPriority, TheReportsChildInheritsTheReportThreadsNice) {
  TempDir dir;
  const auto out = dir / "nice.txt";
  const auto python = dir / "python";
  // The stand-in python3 reports its own nice value (its stat's 19th field; "(python)" holds no space).
  std::ofstream(python) << "#!/bin/sh\ncut -d' ' -f19 /proc/$$/stat > " << out << ".part && mv " << out << ".part "
                        << out << "\nexit 1\n";
  ::chmod(python.c_str(), 0755);
  ReportService::Options o{dir / "reports", dir / "sock", python.string(), "v1"};
  o.nice = 5;
  const int expected = lowered(5);
  ReportService reports(o);
  reports.request("run-1");
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!std::filesystem::exists(out)) {
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "the stand-in python never ran";
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  int nice = -100;
  std::ifstream(out) >> nice;
  EXPECT_EQ(nice, expected);
}

TEST(ThreadPriority, TheEmbeddedSimulatorRunsAtItsConfiguredNice) {
  TempDir dir;
  const auto sim = dir / "colorlab-sim";
  std::ofstream(sim) << "#!/bin/sh\necho '{\"instruments\": []}'\nexec sleep 600\n";
  ::chmod(sim.c_str(), 0755);
  for (int steps : {0, 6}) {
    SimulatorConfig c;
    c.nice = steps;
    const int expected = lowered(steps);
    EmbeddedSim s(sim, c, dir / "scratch");
    EXPECT_EQ(core::nice_in_stat("/proc/" + std::to_string(s.pid()) + "/stat"), expected) << steps;
  }
}

TEST(ThreadPriority, PriorityConfigHasDefaultsAndRefusesNonsense) {
  auto d = parse_config("", "d.toml");
  EXPECT_EQ(d.priority.heavy_work_nice, 0);  // opt-in until a quiet-machine A/B shows it helps (configuration.md)
  EXPECT_EQ(d.priority.simulator_nice, 0);
  auto c = parse_config("[priority]\nheavy_work_nice = 0\nsimulator_nice = 19\n", "c.toml");
  EXPECT_EQ(c.priority.heavy_work_nice, 0);
  EXPECT_EQ(c.priority.simulator_nice, 19);
  for (const char* bad : {"[priority]\nheavy_work_nice = 20\n", "[priority]\nsimulator_nice = -1\n",
                          "[priority]\nheavy_work_nice = 2.5\n", "[priority]\nheavy_work_nice = \"low\"\n",
                          "[priority]\nworkers = 3\n", "priority = 3\n"}) {
    try {
      parse_config(bad, "bad.toml");
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("priority"), std::string::npos) << e.what();
    }
  }
}

TEST(ThreadPriority, AStatFileThatIsNotOneIsATypedError) {
  TempDir dir;
  std::ofstream(dir / "stat") << "not a stat line";
  EXPECT_THROW(core::nice_in_stat(dir / "stat"), Error);
  EXPECT_THROW(core::nice_in_stat(dir / "missing"), Error);
  std::ofstream(dir / "short") << "1 (x y) S 1 2";
  EXPECT_THROW(core::nice_in_stat(dir / "short"), Error);
}

}  // namespace
}  // namespace colorlab::daemon
