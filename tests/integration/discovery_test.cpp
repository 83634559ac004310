// Instruments that come and go: colorlabd watches its configured ports, records each arrival and
// departure in the event log (GET /v1/events), lists what is present (GET /v1/ports), connects an
// instrument when its port appears and releases it when it goes.
#include <fstream>
#include <thread>

#include <gtest/gtest.h>

#include "colorlab/testing/daemon.hpp"
#include "lab_fixture.hpp"

using colorlab::testing::Process;
using colorlab::testing::TempDir;
using nlohmann::json;

namespace {

template <class Pred>
bool eventually(Pred pred, std::chrono::seconds limit = std::chrono::seconds(15)) {
  auto deadline = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < deadline) {
    if (pred()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return false;
}

}  // namespace

TEST(Discovery, DaemonReportsInstrumentsThatComeAndGo) {
  TempDir dir;
  Process sim({colorlab::testing::bin_path("colorlab-sim"), "--config",
               colorlab::testing::write_sim_config_without_camera(dir.path()), "--time-scale", "20", "--control",
               (dir / "sim.sock").string()},
              dir / "sim.log");
  auto line = sim.read_line(std::chrono::seconds(20));
  ASSERT_TRUE(line);
  std::string pty;
  json announcement = json::parse(*line);
  for (const auto& i : announcement["instruments"]) {
    if (i["kind"] == "ls110") pty = i["port"];
  }
  ASSERT_FALSE(pty.empty()) << *line;

  auto link = dir / "ls110-port";  // stands in for /dev/colorlab/ls110, which udev creates on plug-in
  std::ofstream(dir / "colorlabd.toml") << "state_dir = \"state\"\nlisten = \"127.0.0.1:0\"\n\n[[instrument]]\n"
                                        << "id = \"meter\"\nkind = \"ls110\"\nport = \"" << link.string()
                                        << "\"\nsimulated = true\n";
  Process daemon({colorlab::testing::bin_path("colorlabd"), "--config", (dir / "colorlabd.toml").string()},
                 dir / "colorlabd.log");
  std::string url = colorlab::testing::wait_for_endpoint(dir / "state", daemon.pid())["url"];
  auto get = [&](const std::string& path) {
    auto r = colorlab::testing::run_command({"/usr/bin/curl", "-sf", url + path});
    EXPECT_EQ(r.exit_code, 0) << path;
    return json::parse(r.out.empty() ? "null" : r.out);
  };
  auto instrument_state = [&] { return get("/v1/instruments")["items"][0]["state"].get<std::string>(); };

  std::this_thread::sleep_for(std::chrono::milliseconds(600));  // a couple of discovery ticks with nothing plugged in
  EXPECT_TRUE(get("/v1/ports")["items"].empty());
  // Configured but not up: absent, with the missing path as its reason (issue 25).
  EXPECT_EQ(instrument_state(), "absent");
  EXPECT_NE(get("/v1/instruments")["items"][0].value("reason", "").find(link.string()), std::string::npos);

  std::filesystem::create_symlink(pty, link);  // plugged in
  ASSERT_TRUE(eventually([&] { return get("/v1/ports")["items"].size() == 1; }));
  EXPECT_EQ(get("/v1/ports")["items"][0]["id"], "meter");
  ASSERT_TRUE(eventually([&] { return instrument_state() == "ready"; })) << "connects when its port appears";

  std::filesystem::remove(link);  // unplugged
  ASSERT_TRUE(eventually([&] { return get("/v1/ports")["items"].empty(); }));
  EXPECT_TRUE(eventually([&] { return instrument_state() == "absent"; }));

  json events = get("/v1/events?topic=instrument");
  ASSERT_EQ(events["items"].size(), 2u) << events.dump();
  EXPECT_EQ(events["items"][0]["payload"]["event"], "added");
  EXPECT_EQ(events["items"][1]["payload"]["event"], "removed");
  EXPECT_EQ(events["items"][1]["payload"]["id"], "meter");
  // Resuming after the last seen event returns nothing new.
  json none = get("/v1/events?topic=instrument&after=" + std::to_string(events["last_seq"].get<long long>()));
  EXPECT_TRUE(none["items"].empty());
}
