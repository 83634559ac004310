// node-dmx as an independent client of the simulated DMX USB Pro: npm `dmx` 0.25.1 (pinned with its
// serialport 11 by tests/clients/node-dmx/package-lock.json, installed by this test's setup with npm ci),
// whose drivers/enttec-usb-dmx-pro.js opens the port at 250000 8N2 and, every 1000/dmx_speed ms (40 frames/s),
// writes one label 6 packet of the whole universe: 7E 06, length 513, start code 00, 512 slots, E7.
// It never asks the widget anything, so the simulator's truth (control channel) is the only witness.
#include <signal.h>

#include "../sim/serial/sim_process.hpp"
#include "client_support.hpp"
#include "colorlab/testing/process.hpp"

using colorlab::test::SimProcess;
using colorlab::test::truth_slots;
using colorlab::test::wait_for;
using colorlab::testing::on_path;
using colorlab::testing::Process;
using colorlab::testing::run_command;
using nlohmann::json;

namespace {

const char* kLab = R"(
[ls110]
enabled = false
[spectrolino]
enabled = false
[dslr]
enabled = false
)";

// The next line drive.js prints, or a failure naming its log.
std::string next_line(Process& node, const std::string& log) {
  auto line = node.read_line(std::chrono::seconds(20));
  EXPECT_TRUE(line) << "node-dmx printed nothing within 20 s (see " << log << ")";
  return line.value_or("");
}

}  // namespace

TEST(NodeDmxClient, StreamsUniversesThatDriveTheCabinet) {
  COLORLAB_REQUIRE_CLIENT(on_path("node") && on_path("npm"), "node and npm are not installed");
  const std::string dir = NODE_DMX_DIR;
  auto installed = run_command({"/bin/sh", std::string(COLORLAB_SOURCE_DIR) + "/tests/clients/node-dmx/install.sh", dir},
                               std::chrono::seconds(240));
  ASSERT_EQ(installed.exit_code, 0) << "npm ci of tests/clients/node-dmx failed:\n"
                                    << installed.out << installed.err;

  SimProcess sim(kLab);
  const std::string log = (sim.dir() / "node-dmx.log").string();
  // Scene 0: D65 (channel 1) on, dimmer (channel 6) at 64. Scene 1: D65 off, CWF (3) and UV (5) on, dimmer full.
  Process node({colorlab::test::tool_path("node"), dir + "/drive.js", sim.port("dmx"), R"({"1":255,"6":64})", R"({"1":0,"3":200,"5":128,"6":255})"},
               log);
  ASSERT_EQ(next_line(node, log), "scene 0");

  json truth;
  std::string seen;
  ASSERT_TRUE(wait_for(
      [&](std::string& s) {
        truth = sim.control({{"cmd", "truth"}});
        s = truth.dump();
        return truth_slots(truth, 6) == std::vector<int>{255, 0, 0, 0, 0, 64};
      },
      std::chrono::seconds(20), seen))
      << "the widget never received scene 0; truth: " << seen;
  EXPECT_EQ(truth["lamps_on"], json::array({"D65"}));
  EXPECT_NEAR(truth["dimmer"].get<double>(), 64 * 100.0 / 255, 1e-9);
  EXPECT_EQ(truth["dmx"]["slot_count"], 512) << "node-dmx always sends the whole universe";

  // The client streams on its own: with nothing new to say, its packets keep arriving.
  const std::uint64_t packets = truth["dmx"]["packets"];
  EXPECT_TRUE(wait_for(
      [&](std::string& s) {
        truth = sim.control({{"cmd", "truth"}});
        s = truth["dmx"].dump();
        return truth["dmx"]["packets"].get<std::uint64_t>() >= packets + 10;
      },
      std::chrono::seconds(20), seen))
      << "node-dmx stopped streaming after " << packets << " packets: " << seen;
  EXPECT_EQ(truth_slots(truth, 6), (std::vector<int>{255, 0, 0, 0, 0, 64})) << "repeats of the same universe";

  node.signal(SIGUSR1);
  ASSERT_EQ(next_line(node, log), "scene 1");
  EXPECT_TRUE(wait_for(
      [&](std::string& s) {
        truth = sim.control({{"cmd", "truth"}});
        s = truth.dump();
        return truth_slots(truth, 6) == std::vector<int>{0, 0, 200, 0, 128, 255};
      },
      std::chrono::seconds(20), seen))
      << "the widget never received scene 1; truth: " << seen;
  EXPECT_EQ(truth["lamps_on"], json::array({"CWF", "UV"}));
  EXPECT_NEAR(truth["dimmer"].get<double>(), 100.0, 1e-9);
  EXPECT_EQ(truth["dmx"]["bad_frames"], 0) << "every streamed packet is a well-formed label 6 frame";
  EXPECT_EQ(truth["dmx"]["rejected_requests"], 0);

  node.signal(SIGTERM);
  EXPECT_EQ(node.wait(std::chrono::seconds(10)), 0) << "node-dmx closes the port and exits on SIGTERM (see " << log << ")";
}
