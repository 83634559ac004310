#pragma once
// Shared by the suspend tests (suspend_test.cpp, suspend_camera_test.cpp): the embedded simulated lab's control
// channel, to inject a fault into a running execution, and the waits around a suspension.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "colorlab/sim/control_channel.hpp"
#include "resume_support.hpp"

namespace colorlab::testing::suspend {

using nlohmann::json;

inline constexpr double kTimeScale = 100;
// Lab seconds: 0.2 s of wall time at the time scale (the engine's floor).
inline constexpr const char* kSuspendConfig = "[campaigns]\nsuspend_retry_s = 20\nsuspend_settle_s = 20\n";

inline std::filesystem::path control_socket(const DaemonProcess& daemon) {
  json endpoint = json::parse(std::ifstream(daemon.state_dir() / "colorlabd.endpoint"));
  return endpoint.at("simulator_control").get<std::string>();
}

inline json control(const DaemonProcess& daemon, const json& command) {
  json answer = sim::send_control_command(control_socket(daemon), command);
  EXPECT_TRUE(answer.value("ok", false)) << answer.dump();
  return answer;
}

inline std::size_t measurements_of(const client::ApiClient& api, const json& execution) {
  return colorlab::client::fetch_run(api, execution["run_id"].get<std::string>())["measurements"].size();
}

inline void wait_for_measurements(const client::ApiClient& api, const json& execution, std::size_t n) {
  for (int i = 0; i < 600 && measurements_of(api, execution) < n; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_GE(measurements_of(api, execution), n) << "the campaign did not get going";
}

// Polls until the execution is suspended; returns its reason ("" if it never was).
inline std::string wait_suspended(const client::ApiClient& api, const json& execution, std::chrono::seconds timeout) {
  auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    json e = api.get("/v1/executions/" + execution["id"].get<std::string>());
    if (e["status"] == "suspended") return e.value("reason", std::string("(no reason)"));
    EXPECT_NE(e["status"], "finished_error") << e.dump(2);
    if (e["status"] == "finished_error") return "";
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return "";
}

}  // namespace colorlab::testing::suspend
