// colorlabd's embedded simulated lab brings the simulated DSLR with it: the announcement's
// `simdslr` entry becomes an instrument the daemon connects (its socket is watched like a serial
// port), and a camera campaign captures through it when no GigE Vision camera is present.
#include <gtest/gtest.h>

#include <fstream>
#include <thread>

#include "resume_support.hpp"

using namespace colorlab::testing;
using nlohmann::json;

TEST(EmbeddedLabDslr, TheDaemonConnectsTheAnnouncedDslrAndCapturesThroughIt) {
  TempDir dir;
  std::ofstream(dir / "lab.toml") << "[genicam]\nenabled = false\n[dslr]\nsize = [640, 428]\n";
  std::ofstream(dir / "colorlabd.toml") << "[simulator]\nenabled = true\ntime_scale = 200\nseed = 3\nconfig = \"lab.toml\"\n";
  DaemonProcess daemon(dir / "state", dir / "colorlabd.toml", dir / "colorlabd.log");
  auto api = api_for(daemon);

  json dslr = json::object();
  for (int i = 0; i < 200 && dslr.value("state", std::string()) != "ready"; ++i) {
    const json listed = api.get("/v1/instruments");
    for (const auto& item : listed["items"]) {
      if (item["id"] == "dslr") dslr = item;
    }
    if (dslr.value("state", std::string()) != "ready") std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_EQ(dslr.value("state", std::string()), "ready")
      << dslr.dump() << "\n"
      << api.get("/v1/instruments").dump() << "\n"
      << shell_output("cat " + (dir / "colorlabd.log").string());
  EXPECT_EQ(dslr["kind"], "dslr");
  EXPECT_EQ(dslr["serial"], "SIM20D0001");
  EXPECT_TRUE(dslr["simulated"]);
  EXPECT_NE(std::find(dslr["capabilities"].begin(), dslr["capabilities"].end(), "camera"), dslr["capabilities"].end());

  // Without a GenICam camera the DSLR is the lab's camera: frame-average runs on its DNGs.
  auto e = api.post("/v1/executions", {{"campaign", "frame-average"}, {"params", {{"frames", 4}}}});
  auto done = wait_terminal(api, e["id"]);
  ASSERT_EQ(done["status"], "finished_ok") << done.dump();
  json run = colorlab::client::fetch_run(api, e["run_id"].get<std::string>());
  EXPECT_EQ(run["measurements"].size(), 9u);  // subsets 1, 2, 4 × R, G, B
  for (const auto& m : run["measurements"]) EXPECT_TRUE(m["simulated"]);
}
