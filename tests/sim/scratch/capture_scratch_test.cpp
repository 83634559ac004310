// A colorlab-sim killed with SIGKILL cannot remove its DSLR card folder; the next simulator started on
// the same scratch root must, without touching the folder of a simulator that still runs (the tests
// run several in parallel). Real processes, SIGKILL, no sleeps: each simulator has created its folder
// once it has announced itself.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>

#include <nlohmann/json.hpp>

#include "colorlab/sim/capture_scratch.hpp"
#include "colorlab/testing/process.hpp"
#include "colorlab/testing/temp_dir.hpp"
#include "scoped_env.hpp"

namespace fs = std::filesystem;
using colorlab::testing::Process;
using colorlab::testing::TempDir;

namespace {

// A small DSLR and nothing else that needs a shared resource (the GigE Vision fake takes a loopback lock).
constexpr const char* kLab = "[genicam]\nenabled = false\n[dslr]\nsize = [128, 96]\n";

struct Sim {
  std::unique_ptr<Process> process;
  fs::path capture_dir;

  fs::path dslr_socket;

  Sim(const TempDir& dir, const std::string& name) {
    std::ofstream(dir / "lab.toml") << kLab;
    // The DSLR's socket goes to $XDG_RUNTIME_DIR when the configuration names none: this test's own.
    fs::create_directories(dir / "run");
    colorlab::testing::ScopedEnv env{{"XDG_RUNTIME_DIR", (dir / "run").string()}};
    process = std::make_unique<Process>(
        std::vector<std::string>{colorlab::testing::bin_path("colorlab-sim"), "--config", (dir / "lab.toml").string(),
                                 "--control", (dir / (name + ".sock")).string(), "--scratch-dir", (dir / "scratch").string()},
        dir / (name + ".log"));
    auto line = process->read_line(std::chrono::seconds(30));
    if (!line) throw std::runtime_error("colorlab-sim " + name + " did not announce itself (see " + (dir / (name + ".log")).string() + ")");
    const auto announcement = nlohmann::json::parse(*line);
    for (const auto& i : announcement["instruments"]) {
      if (i.contains("capture_dir")) {
        capture_dir = i["capture_dir"].get<std::string>();
        dslr_socket = i["port"].get<std::string>();
      }
    }
    if (capture_dir.empty()) throw std::runtime_error("colorlab-sim " + name + " announced no DSLR capture_dir: " + *line);
  }
};

}  // namespace

TEST(SimCaptureScratch, ASuccessorReclaimsAKilledSimulatorsFolderAndKeepsALiveOnes) {
  TempDir dir;
  Sim killed(dir, "killed");
  Sim live(dir, "live");
  EXPECT_EQ(killed.capture_dir, colorlab::sim::default_capture_dir(dir / "scratch", killed.process->pid()));
  ASSERT_TRUE(fs::is_directory(killed.capture_dir));
  ASSERT_TRUE(fs::is_directory(live.capture_dir));
  // A name that only looks like ours, and a file, are none of the reclaimer's business.
  fs::create_directories(dir / "scratch" / "colorlab-sim-12x-dslr");
  std::ofstream(dir / "scratch" / "notes.txt") << "kept";

  killed.process->signal(SIGKILL);
  ASSERT_TRUE(killed.process->wait(std::chrono::seconds(20))) << "colorlab-sim did not die of SIGKILL within 20 s";
  ASSERT_TRUE(fs::is_directory(killed.capture_dir)) << "a SIGKILLed simulator cannot have removed its own folder";
  ASSERT_EQ(killed.dslr_socket.parent_path(), dir / "run");
  ASSERT_TRUE(fs::exists(killed.dslr_socket)) << "a SIGKILLed simulator cannot have removed its socket";

  Sim successor(dir, "successor");
  EXPECT_FALSE(fs::exists(killed.capture_dir)) << "the killed simulator's folder was not reclaimed";
  EXPECT_TRUE(fs::is_directory(live.capture_dir)) << "a live simulator's folder was removed";
  EXPECT_FALSE(fs::exists(killed.dslr_socket)) << "the killed simulator's socket was not reclaimed";
  EXPECT_TRUE(fs::exists(live.dslr_socket)) << "a live simulator's socket was removed";
  EXPECT_TRUE(fs::is_directory(successor.capture_dir));
  EXPECT_TRUE(fs::is_directory(dir / "scratch" / "colorlab-sim-12x-dslr"));
  EXPECT_TRUE(fs::exists(dir / "scratch" / "notes.txt"));

  // A simulator that exits normally still removes its own folder.
  live.process->signal(SIGTERM);
  ASSERT_TRUE(live.process->wait(std::chrono::seconds(20))) << "colorlab-sim did not exit on SIGTERM within 20 s";
  EXPECT_FALSE(fs::exists(live.capture_dir));
}

TEST(SimCaptureScratch, AZombieIsGoneAndALiveProcessIsNot) {
  EXPECT_FALSE(colorlab::sim::process_is_gone(::getpid()));
  EXPECT_FALSE(colorlab::sim::process_is_gone(1)) << "pid 1 runs (EPERM must not count as gone)";
  pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ASSERT_GT(child, 0);
  // Exited but not reaped: a zombie until waitpid. waitid(WNOWAIT) waits for the exit without reaping it.
  siginfo_t info{};
  ASSERT_EQ(::waitid(P_PID, static_cast<id_t>(child), &info, WEXITED | WNOWAIT), 0);
  EXPECT_TRUE(colorlab::sim::process_is_gone(child)) << "a zombie no longer runs";
  int status = 0;
  ::waitpid(child, &status, 0);
  EXPECT_TRUE(colorlab::sim::process_is_gone(child));
}
