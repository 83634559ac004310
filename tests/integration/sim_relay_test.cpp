// The HID lamp relay where the lab configuration names one: colorlab-sim serves its scripted
// dcttech board on a Unix socket, the factory's `hidrelay` reaches it with port "unix:/path", and
// what the driver switches is what the scene's lamps do (read back through the control channel's
// truth, the LS-110's view included).
#include <gtest/gtest.h>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/use_future.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/hid_relay.hpp"
#include "sim_lab_process.hpp"

using colorlab::Error;
using colorlab::ErrorClass;
using colorlab::testing::SimLabProcess;
using nlohmann::json;

namespace {

template <class Awaitable>
void run(boost::asio::io_context& io, Awaitable a) {
  auto done = boost::asio::co_spawn(io, std::move(a), boost::asio::use_future);
  io.restart();
  io.run();
  done.get();
}

std::vector<std::string> scene_lamps(SimLabProcess& sim) {
  return sim.control({{"cmd", "truth"}})["lamps_on"].get<std::vector<std::string>>();
}

struct RelayRig {
  SimLabProcess sim{"[relay]\nenabled = true\nlamps = { D65 = 1, TL84 = 2, A = 3 }\n"};
  boost::asio::io_context io;
  std::shared_ptr<colorlab::drivers::HidRelay> relay;

  RelayRig() {
    auto config = sim.config_for("hidrelay");
    relay = std::dynamic_pointer_cast<colorlab::drivers::HidRelay>(colorlab::drivers::make_instrument(io.get_executor(), config));
    if (!relay) throw std::runtime_error("the factory's hidrelay is not a HidRelay");
    run(io, relay->connect());
  }
};

}  // namespace

TEST(SimRelay, OffByDefaultAndAnnouncedWithItsLampMapWhenConfigured) {
  SimLabProcess plain("");
  for (const auto& i : plain.announcement["instruments"]) EXPECT_NE(i["kind"], "hidrelay");
  RelayRig rig;
  const auto config = rig.sim.config_for("hidrelay");
  EXPECT_TRUE(config.port.starts_with("unix:")) << config.port;
  EXPECT_EQ(config.options["lamps"], (json{{"D65", 1}, {"TL84", 2}, {"A", 3}}));
  EXPECT_EQ(rig.relay->identity().serial, "CLRLB");
  EXPECT_EQ(rig.relay->relay_count(), 8);
  // The board starts with the relays of the scene's lamps closed: both tell the same story.
  EXPECT_EQ(rig.relay->lamps_on(), std::vector<std::string>{"D65"});
}

TEST(SimRelay, SwitchingThroughTheSocketDrivesTheScenesLamps) {
  RelayRig rig;
  const double d65 = rig.sim.control({{"cmd", "truth"}})["ls110"]["luminance"];
  ASSERT_GT(d65, 0);

  run(rig.io, rig.relay->set_lamps({"TL84"}));
  EXPECT_EQ(scene_lamps(rig.sim), std::vector<std::string>{"TL84"});
  json t = rig.sim.control({{"cmd", "truth"}});
  EXPECT_EQ(t["relay"]["mask"], 0b010);
  EXPECT_GT(t["ls110"]["luminance"].get<double>(), 0);

  run(rig.io, rig.relay->set_lamps({}));
  EXPECT_TRUE(scene_lamps(rig.sim).empty());
  t = rig.sim.control({{"cmd", "truth"}});
  EXPECT_EQ(t["relay"]["mask"], 0);
  EXPECT_EQ(t["ls110"]["luminance"].get<double>(), 0.0) << "the meter sees a dark cabinet";

  run(rig.io, rig.relay->set_lamps({"A"}));
  EXPECT_EQ(scene_lamps(rig.sim), std::vector<std::string>{"A"});
  EXPECT_EQ(rig.relay->lamps_on(), std::vector<std::string>{"A"});
}

TEST(SimRelay, AStuckRelayAndAnUnpluggedBoardAreTypedErrors) {
  RelayRig rig;
  rig.sim.control({{"cmd", "fault"}, {"instrument", "relay"}, {"faults", {{"stuck_mask", 0b010}}}});
  try {
    run(rig.io, rig.relay->set_lamps({"TL84"}));
    ADD_FAILURE() << "a stuck relay switched";
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::hardware_fail) << e.what();
  }
  EXPECT_TRUE(scene_lamps(rig.sim).empty()) << "break before make: D65 went off, TL84 never came on";

  // Unplugged, found again on the second open: the driver's reconnect gets there by itself.
  rig.sim.control({
      {"cmd", "fault"},
      {"instrument", "relay"},
      {"faults", {{"stuck_mask", 0}, {"unplugged", true}, {"replug_after_opens", 2}}},
  });
  run(rig.io, rig.relay->set_lamps({"A"}));
  EXPECT_EQ(scene_lamps(rig.sim), std::vector<std::string>{"A"});

  // Gone for good (colorlab-sim stopped): no_comms, not a hang.
  rig.sim.process->signal(SIGKILL);
  rig.sim.process->wait(std::chrono::seconds(10));
  try {
    run(rig.io, rig.relay->set_lamps({"D65"}));
    ADD_FAILURE() << "switched a board whose simulator is gone";
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::no_comms) << e.what();
  }
}
