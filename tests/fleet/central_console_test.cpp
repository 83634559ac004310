// The web console against colorlab-central with only the URL changed (issue 22): two benches ship into a real
// PostgreSQL 15 and Swift s3api on 127.0.0.1, colorlab-central serves the console's files at / with a bench's
// Content-Security-Policy, and headless Chromium (central_console_check.py) finds the Runs page across both benches
// with the bench column and filter, opens a run to its measurements and frames, and is offered no control. Fails,
// not skips, without the servers or Chromium (scripts/setup.sh installs them).
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "colorlab/testing/process.hpp"
#include "content_security.hpp"
#include "fleet_servers.hpp"
#include "sim_bench.hpp"
#include "web_tls_servers.hpp"

namespace fs = std::filesystem;
using namespace colorlab;
namespace ct = colorlab::testing;
using namespace colorlab::fleet_test;
using nlohmann::json;
using protocol::ExecutionStatus;

namespace {

SharedServers& servers() { return web_tls_servers(); }

// The response headers of one GET with curl (lower-case names), and its status.
std::map<std::string, std::string> head_of(const std::string& url, int& status) {
  auto r = ct::run_command({"/usr/bin/curl", "-s", "-o", "/dev/null", "-D", "-", url}, std::chrono::seconds(30));
  std::map<std::string, std::string> out;
  std::istringstream in(r.out);
  std::string line;
  status = 0;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.rfind("HTTP/", 0) == 0) {
      status = std::stoi(line.substr(line.find(' ') + 1, 3));
      continue;
    }
    auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string name = line.substr(0, colon);
    for (auto& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    out[name] = line.substr(std::min(line.size(), line.find_first_not_of(' ', colon + 1)));
  }
  return out;
}

TEST(CentralConsole, TheRunsPageWorksAgainstCentralWithOnlyTheUrlChanged) {
  const std::string missing = missing_tools();
  if (!missing.empty()) FAIL() << "this test needs:" << missing << " (scripts/setup.sh installs them)";
  const auto t0 = std::chrono::steady_clock::now();
  auto& s = servers();
  const std::string name = s.fresh_for_current_test();
  const fs::path dir = s.root / name;
  const ShipTarget t{s.pg->conninfo(name), s.swift->endpoint(), name, SwiftServer::kAccessKey, SwiftServer::kSecretKey};
  const auto t1 = std::chrono::steady_clock::now();

  // Two benches: north with frames on every third patch, south with an aborted run among its own.
  SimBench north(dir / "bench-north", "bench-north", 5);
  SimBench south(dir / "bench-south", "bench-south", 6);
  json expected = {{"benches", {{"bench-north", json::array()}, {"bench-south", json::array()}}}};
  for (int i = 0; i < 3; ++i) {
    expected["benches"]["bench-north"].push_back(north.run_campaign(ExecutionStatus::finished_ok, 60, 3));
  }
  expected["benches"]["bench-south"].push_back(south.run_campaign(ExecutionStatus::finished_ok, 8, 0));
  expected["benches"]["bench-south"].push_back(south.run_campaign(ExecutionStatus::aborted, 4, 0));
  for (auto* b : {&north, &south}) {
    auto r = ct::run_command({ct::bin_path("colorlab-ship"), "--config", b->write_config(t).string(), "once"},
                             std::chrono::seconds(120));
    ASSERT_EQ(r.exit_code, 0) << b->bench_id() << ": " << r.err;
  }
  // The run the browser opens: 60 measurements (more than a page of 50) and 20 frames.
  expected["open"] = expected["benches"]["bench-north"][1];
  const auto t2 = std::chrono::steady_clock::now();

  const fs::path c = dir / "central";
  fs::create_directories(c);
  std::ofstream(c / "s3-access-key") << t.access_key << "\n";
  std::ofstream(c / "s3-secret-key") << t.secret_key << "\n";
  std::ofstream(c / "central.toml") << "state_dir = \"" << (c / "state").string() << "\"\n[central]\n"
                                    << "listen = \"127.0.0.1\"\nport = 0\nthreads = 2\npostgres = \"" << t.postgres
                                    << "\"\ns3_endpoint = \"" << t.s3_endpoint << "\"\nbucket = \"" << name << "\"\n"
                                    << "access_key_file = \"s3-access-key\"\nsecret_key_file = \"s3-secret-key\"\n";
  const std::string config = (c / "central.toml").string();
  auto made = ct::run_command({ct::bin_path("colorlab-central"), "--config", config, "keys", "create", "console"});
  ASSERT_EQ(made.exit_code, 0) << made.err;
  const std::string key = json::parse(made.out)["key"];
  // COLORLAB_CONSOLE_DIR unset: central serves the build tree's copy (share/colorlab/console), as installed.
  ct::Process central({"/usr/bin/env", "-u", "COLORLAB_CONSOLE_DIR", ct::bin_path("colorlab-central"), "--config",
                       config, "serve"},
                      c / "central.log");
  auto line = central.read_line(std::chrono::seconds(60));
  ASSERT_TRUE(line) << "colorlab-central did not start: " << read_all(c / "central.log");
  const std::string url = json::parse(*line)["url"];

  // The console's files with the bench's own headers: the same policy, no sniffing, revalidated.
  for (const std::string path : {"/", "/js/main.js", "/js/pages/runs.js", "/css/console.css"}) {
    int status = 0;
    auto h = head_of(url + path, status);
    EXPECT_EQ(status, 200) << path;
    EXPECT_EQ(h["content-security-policy"], daemon::kConsolePolicy) << path;
    EXPECT_EQ(h["x-content-type-options"], "nosniff") << path;
    EXPECT_EQ(h["cache-control"], "no-cache") << path;
  }

  const auto t3 = std::chrono::steady_clock::now();
  const fs::path expectations = dir / "expected.json";
  std::ofstream(expectations) << expected.dump();
  auto browser = ct::run_command(
      {"/usr/bin/env", "PYTHONPATH=" COLORLAB_SOURCE_DIR "/client/python", "PYTHONDONTWRITEBYTECODE=1",
       "COLORLAB_BIN_DIR=" COLORLAB_BIN_DIR, "COLORLAB_SOURCE_DIR=" COLORLAB_SOURCE_DIR,
       "COLORLAB_ARTIFACT_DIR=" + (fs::path(COLORLAB_BIN_DIR).parent_path() / "test-artifacts" / "central-console").string(),
       "/usr/bin/python3", COLORLAB_SOURCE_DIR "/tests/fleet/central_console_check.py", url, key, expectations.string()},
      std::chrono::seconds(180));
  EXPECT_EQ(browser.exit_code, 0) << browser.out << browser.err;
  EXPECT_NE(browser.out.find("the console works on central"), std::string::npos) << browser.out << browser.err;
  const auto t4 = std::chrono::steady_clock::now();
  auto sec = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
  std::cerr << "central console: servers " << sec(t0, t1) << " s, two benches shipped " << sec(t1, t2)
            << " s, central up " << sec(t2, t3) << " s, Chromium " << sec(t3, t4) << " s\n";
}

}  // namespace
