#include "resume_support.hpp"

#include <sqlite3.h>

#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <stdexcept>
#include <thread>

#include <gtest/gtest.h>

#include "colorlab/protocol/states.hpp"

namespace colorlab::testing {

std::filesystem::path write_daemon_config(const std::filesystem::path& dir, double time_scale, std::uint64_t seed,
                                          const std::string& extra, bool camera) {
  auto path = dir / "colorlabd.toml";
  std::ofstream out(path);
  out << "[simulator]\nenabled = true\ntime_scale = " << time_scale << "\nseed = " << seed << "\n";
  if (!camera) {
    std::ofstream(dir / "lab.toml") << "[genicam]\nenabled = false\n";
    out << "config = \"lab.toml\"\n";
  }
  out << extra;
  return path;
}

client::ApiClient api_for(const DaemonProcess& daemon) {
  // The Unix socket: these tests start and control executions, which loopback TCP allows only with a key.
  client::Endpoint socket;
  socket.unix_socket = daemon.unix_socket();
  return client::ApiClient(socket, std::chrono::seconds(30));
}

void write_campaign(const std::filesystem::path& dir, const std::string& file_name, std::string_view source) {
  const auto folder = dir / "state" / "campaigns";
  std::filesystem::create_directories(folder);
  std::ofstream out(folder / file_name, std::ios::binary | std::ios::trunc);
  out.write(source.data(), static_cast<std::streamsize>(source.size()));
  out.close();
  if (!out) throw std::runtime_error("could not write the campaign script " + (folder / file_name).string());
}

nlohmann::json wait_terminal(const client::ApiClient& api, const std::string& execution_id, std::chrono::seconds timeout) {
  auto deadline = std::chrono::steady_clock::now() + timeout;
  nlohmann::json e;
  while (std::chrono::steady_clock::now() < deadline) {
    e = api.get("/v1/executions/" + execution_id);
    auto status = protocol::execution_status_from_string(e.value("status", std::string()));
    if (status && protocol::is_terminal(*status)) return e;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return e;
}

std::string integrity_check(const std::filesystem::path& state_dir) {
  sqlite3* db = nullptr;
  std::string result = "cannot open";
  if (sqlite3_open_v2((state_dir / "colorlab.db").c_str(), &db, SQLITE_OPEN_READWRITE, nullptr) == SQLITE_OK) {
    sqlite3_stmt* st = nullptr;
    if (sqlite3_prepare_v2(db, "PRAGMA integrity_check", -1, &st, nullptr) == SQLITE_OK && sqlite3_step(st) == SQLITE_ROW) {
      result = reinterpret_cast<const char*>(sqlite3_column_text(st, 0));
    }
    sqlite3_finalize(st);
  }
  sqlite3_close(db);
  return result;
}

nlohmann::json run_to_end(const client::ApiClient& api, const std::string& campaign, const nlohmann::json& params,
                          std::chrono::seconds timeout) {
  auto e = api.post("/v1/executions", {{"campaign", campaign}, {"params", params}});
  auto done = wait_terminal(api, e["id"], timeout);
  EXPECT_EQ(done["status"], "finished_ok") << done.dump(2);
  return colorlab::client::fetch_run(api, e["run_id"].get<std::string>());
}

namespace {

struct KillNineDaemon {
  TempDir dir;
  DaemonProcess daemon;
  explicit KillNineDaemon(const KillNineCase& c)
      : daemon(dir / "state", [&] {
          auto config = write_daemon_config(dir.path(), c.time_scale, c.seed);
          if (!c.lab_toml.empty()) std::ofstream(dir / "lab.toml") << c.lab_toml;
          return config;
        }()) {}
  nlohmann::json params(const KillNineCase& c) const {
    nlohmann::json p = c.params;
    if (c.prepare) p.update(c.prepare(api_for(daemon)));
    return p;
  }
};

}  // namespace

void kill_and_compare(const KillNineCase& c) {
  std::vector<std::string> reference_steps;
  std::map<std::string, double> reference_values;
  int uninterrupted_ms = 0;
  {
    KillNineDaemon d(c);
    const auto params = d.params(c);
    const auto start = std::chrono::steady_clock::now();
    auto run = run_to_end(api_for(d.daemon), c.campaign, params, c.timeout);
    uninterrupted_ms = static_cast<int>(std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - start).count());
    std::cout << "[kill -9] " << c.campaign << " uninterrupted: " << uninterrupted_ms << " ms\n";
    for (const auto& m : run["measurements"]) {
      reference_steps.push_back(m["step"]);
      reference_values[m["step"]] = m["value"].get<double>();
    }
    d.daemon.kill9();
  }
  ASSERT_FALSE(reference_steps.empty());
  int kills_done = 0;
  for (int seed = 1; seed <= c.runs; ++seed) {
    KillNineDaemon d(c);
    auto& daemon = d.daemon;
    auto api = api_for(daemon);
    auto e = api.post("/v1/executions", {{"campaign", c.campaign}, {"params", d.params(c)}});
    std::mt19937 rng(static_cast<unsigned>(seed * 104729));
    for (int k = 0; k < 2; ++k) {
      // 90 %: a run on a fresh daemon is sometimes a little faster than the uninterrupted one was.
      const int max_delay_ms = c.max_delay_ms > 0 ? c.max_delay_ms : std::max(100, uninterrupted_ms * 9 / 10);
      std::this_thread::sleep_for(std::chrono::milliseconds(std::uniform_int_distribution<int>(50, max_delay_ms)(rng)));
      auto before = api.get("/v1/executions/" + e["id"].get<std::string>());
      if (before["status"] != "running" && before["status"] != "waiting") {
        std::cout << "[kill -9] " << c.campaign << " run " << seed << ": not killed, " << before["status"] << "\n";
        break;
      }
      daemon.kill9();
      std::cout << "[kill -9] " << c.campaign << " run " << seed << ": killed at " << before.value("progress", nlohmann::json()).dump() << " "
                << before.value("step", nlohmann::json()).dump() << "\n";
      ++kills_done;
      EXPECT_EQ(integrity_check(daemon.state_dir()), "ok");
      daemon.start();
      api = api_for(daemon);
    }
    auto done = wait_terminal(api, e["id"], c.timeout);
    ASSERT_EQ(done["status"], "finished_ok") << c.campaign << " seed " << seed << ": " << done.dump(2);
    auto run = colorlab::client::fetch_run(api, e["run_id"].get<std::string>());
    std::vector<std::string> steps;
    for (const auto& m : run["measurements"]) {
      steps.push_back(m["step"]);
      const double ref = reference_values[m["step"]];
      EXPECT_NEAR(m["value"].get<double>(), ref, c.tolerance(m, ref)) << c.campaign << " seed " << seed << ": " << m["step"];
    }
    EXPECT_EQ(steps, reference_steps) << c.campaign << " seed " << seed;
    daemon.kill9();
    EXPECT_EQ(integrity_check(daemon.state_dir()), "ok");
  }
  EXPECT_GT(kills_done, 0) << "every run finished before its first kill: the test proved nothing";
}

}  // namespace colorlab::testing
