#include "resume_support.hpp"

#include <sqlite3.h>

#include <fstream>
#include <thread>

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
  return client::ApiClient(client::Endpoint::from_url(daemon.url()), std::chrono::seconds(30));
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

}  // namespace colorlab::testing
