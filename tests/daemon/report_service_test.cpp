// The report service's life cycle with stand-in interpreters (the real report package is tested against a
// running daemon in client/python/tests/integration/test_report_frame_average.py): made once and kept, a
// failure reported with the child's words and retried later, one child at a time, a hung child stopped.
#include <chrono>
#include <fstream>
#include <thread>

#include <sys/stat.h>

#include <gtest/gtest.h>

#include "colorlab/daemon/report_service.hpp"
#include "colorlab/testing/temp_dir.hpp"

using colorlab::daemon::ReportService;
using colorlab::testing::TempDir;
using Kind = ReportService::State::Kind;

namespace {

// A shell script standing in for python3: it gets `-m colorlab.report RUN -o FILE --socket SOCK`.
std::string stand_in(const TempDir& dir, const std::string& name, const std::string& body) {
  const auto path = dir / name;
  std::ofstream(path) << "#!/bin/sh\n"
                      << body << "\n";
  ::chmod(path.c_str(), 0755);
  return path.string();
}

ReportService::State wait_until_not_generating(ReportService& reports, const std::string& run,
                                               std::chrono::seconds within = std::chrono::seconds(20)) {
  const auto deadline = std::chrono::steady_clock::now() + within;
  auto s = reports.request(run);
  while (s.kind == Kind::generating && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    s = reports.request(run);
  }
  return s;
}

TEST(ReportService, MadeOnceThenServedFromTheFile) {
  TempDir dir;
  // Counts its runs, writes the HTML where -o says.
  const auto python = stand_in(dir, "python",
                               "echo run >> \"" + (dir / "count").string() +
                                   "\"\nwhile [ \"$1\" != -o ]; do shift; done\necho '<html>' $2 > \"$2\"");
  ReportService reports({dir / "reports", dir / "sock", python, "v1"});
  EXPECT_EQ(reports.request("run-a").kind, Kind::generating);
  auto s = wait_until_not_generating(reports, "run-a");
  ASSERT_EQ(s.kind, Kind::ready) << s.error;
  EXPECT_EQ(s.file, dir / "reports" / "run-a-v1.html");
  EXPECT_TRUE(std::filesystem::is_regular_file(s.file));
  for (int i = 0; i < 5; ++i) EXPECT_EQ(reports.request("run-a").kind, Kind::ready);
  std::ifstream count(dir / "count");
  std::string all((std::istreambuf_iterator<char>(count)), {});
  EXPECT_EQ(all, "run\n");  // made once
}

TEST(ReportService, AFailureSaysWhatTheChildSaidAndIsRetriedLater) {
  TempDir dir;
  const auto python = stand_in(dir, "python", "echo 'ModuleNotFoundError: No module named matplotlib' >&2\nexit 1");
  ReportService::Options o{dir / "reports", dir / "sock", python, "v1"};
  o.retry_after_failure = std::chrono::seconds(1);
  ReportService reports(o);
  auto s = wait_until_not_generating(reports, "run-b");
  ASSERT_EQ(s.kind, Kind::failed);
  EXPECT_NE(s.error.find("exited 1"), std::string::npos) << s.error;
  EXPECT_NE(s.error.find("No module named matplotlib"), std::string::npos) << s.error;
  EXPECT_NE(s.error.find("python3-matplotlib"), std::string::npos) << s.error;
  EXPECT_EQ(reports.request("run-b").kind, Kind::failed);  // within the retry delay: the same answer
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  EXPECT_EQ(reports.request("run-b").kind, Kind::generating);  // then it tries again
}

TEST(ReportService, AMissingInterpreterIsAFailureNotACrash) {
  TempDir dir;
  ReportService reports({dir / "reports", dir / "sock", (dir / "no-such-python").string(), "v1"});
  auto s = wait_until_not_generating(reports, "run-c");
  ASSERT_EQ(s.kind, Kind::failed);
  EXPECT_NE(s.error.find("no-such-python"), std::string::npos) << s.error;
}

TEST(ReportService, AChildThatHangsIsStoppedAtTheTimeout) {
  TempDir dir;
  ReportService::Options o{dir / "reports", dir / "sock", stand_in(dir, "python", "exec sleep 60"), "v1"};
  o.timeout = std::chrono::seconds(1);
  ReportService reports(o);
  auto s = wait_until_not_generating(reports, "run-d", std::chrono::seconds(15));
  ASSERT_EQ(s.kind, Kind::failed);
  EXPECT_NE(s.error.find("longer than 1 s"), std::string::npos) << s.error;
}

TEST(ReportService, ShuttingDownStopsARunningChild) {
  TempDir dir;
  const auto started = std::chrono::steady_clock::now();
  {
    ReportService reports({dir / "reports", dir / "sock", stand_in(dir, "python", "exec sleep 60"), "v1"});
    reports.request("run-e");
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
  }
  EXPECT_LT(std::chrono::steady_clock::now() - started, std::chrono::seconds(30));
}

}  // namespace
