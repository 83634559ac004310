// The Enttec DMX USB Pro driver against the widget simulator on a pty: discovery by label 10,
// lamps and dimmer through label 6 into the Scene, ramps, the one-lamp rule and link faults.
#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/enttec_dmx.hpp"
#include "colorlab/drivers/factory.hpp"
#include "colorlab/sim/clock.hpp"
#include "colorlab/sim/dmx_sim.hpp"
#include "colorlab/sim/scene.hpp"
#include "run_support.hpp"

namespace colorlab::test {
namespace {

using drivers::EnttecDmx;

class EnttecDmxSimTest : public ::testing::Test {
 protected:
  void SetUp() override {
    clock_ = std::make_shared<sim::SimClock>(1.0);
    sim::SceneConfig sc;
    sc.force_synthetic_chart = true;
    sc.dimmer_percent_at_start = 0;
    scene_ = std::make_unique<sim::Scene>(sc, clock_);
    sim_ = std::make_shared<sim::DmxSim>(io_.get_executor(), *scene_, sim::DmxConfig{}, 3, 1.0);
    sim_->start();
  }
  void TearDown() override {
    sim_->stop();
    settle(io_, std::chrono::milliseconds(5));
  }
  drivers::EnttecDmxOptions options(bool allow_multiple = false) const {
    drivers::EnttecDmxOptions o;
    o.id = "cabinet";
    o.port = sim_->port_path();
    o.simulated = true;
    o.lamps = drivers::LampMap({{"D65", 1}, {"TL84", 2}, {"CWF", 3}, {"A", 4}, {"UV", 5}}, 512, allow_multiple);
    o.dimmer_channel = 6;
    o.reply_timeout = std::chrono::milliseconds(300);
    o.reconnect.initial_backoff = std::chrono::milliseconds(5);
    o.reconnect.max_attempts = 2;
    return o;
  }

  boost::asio::io_context io_;
  std::shared_ptr<sim::SimClock> clock_;
  std::unique_ptr<sim::Scene> scene_;
  std::shared_ptr<sim::DmxSim> sim_;
};

TEST_F(EnttecDmxSimTest, DiscoversWidgetBySerialAndParameters) {
  EnttecDmx d(io_.get_executor(), options());
  run(io_, d.connect());
  EXPECT_EQ(d.state(), drivers::InstrumentState::ready);
  EXPECT_EQ(d.widget_serial(), 0x12345678u) << "serial 12345678 is stored as BCD";
  EXPECT_EQ(d.identity().serial, "12345678");
  EXPECT_EQ(d.firmware() >> 8, 1) << "DMX firmware";
  // What `colorlab instruments` shows; OLA prints the same bytes as "firmware 1.44" (issue 25: it was 1.68).
  EXPECT_EQ(d.identity().firmware, "1.44");
  EXPECT_EQ(sim_->packets(), 0u) << "discovery must not change the light";
}

TEST_F(EnttecDmxSimTest, LampSelectionDrivesTheCabinet) {
  EnttecDmx d(io_.get_executor(), options());
  run(io_, d.connect());
  run(io_, d.set_lamps({"TL84"}));
  settle(io_, std::chrono::milliseconds(20));
  EXPECT_TRUE(scene_->lamp_on(sim::Lamp::tl84));
  EXPECT_FALSE(scene_->lamp_on(sim::Lamp::d65));
  run(io_, d.set_lamps({"D65"}));
  settle(io_, std::chrono::milliseconds(20));
  EXPECT_TRUE(scene_->lamp_on(sim::Lamp::d65));
  EXPECT_FALSE(scene_->lamp_on(sim::Lamp::tl84));
  EXPECT_EQ(d.lamps_on(), std::vector<std::string>{"D65"});
  ASSERT_GE(sim_->universe().size(), 6u);
  EXPECT_EQ(sim_->universe()[0], 255);
  EXPECT_EQ(sim_->universe()[1], 0);
}

TEST_F(EnttecDmxSimTest, SecondLampIsRefusedUnlessAllowed) {
  EnttecDmx d(io_.get_executor(), options());
  run(io_, d.connect());
  run(io_, d.set_lamps({"D65"}));
  try {
    run(io_, d.set_level("A", 0.5));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::conflict);
  }
  EXPECT_THROW(run(io_, d.set_lamps({"D65", "UV"})), Error);

  EnttecDmx mixed(io_.get_executor(), options(true));
  run(io_, mixed.connect());
  run(io_, mixed.set_lamps({"D65", "UV"}));
  settle(io_, std::chrono::milliseconds(20));
  EXPECT_TRUE(scene_->lamp_on(sim::Lamp::d65));
  EXPECT_TRUE(scene_->lamp_on(sim::Lamp::uv));
}

TEST_F(EnttecDmxSimTest, DimmerRampsAtTheConfiguredRateThenSettles) {
  auto o = options();
  o.ramp_per_second = 4.0;  // 0 → full in 0.25 s
  o.frame_interval = std::chrono::milliseconds(10);
  o.settle = std::chrono::milliseconds(30);
  EnttecDmx d(io_.get_executor(), o);
  run(io_, d.connect());
  auto before = sim_->packets();
  auto t0 = std::chrono::steady_clock::now();
  run(io_, d.set_level("dimmer", 1.0));
  auto elapsed = std::chrono::steady_clock::now() - t0;
  settle(io_, std::chrono::milliseconds(20));
  EXPECT_EQ(sim_->packets() - before, 25u) << "0.25 s of ramp at one frame per 10 ms";
  EXPECT_EQ(sim_->universe()[5], 255);
  EXPECT_NEAR(scene_->dimmer(), 100.0, 0.5);
  EXPECT_GE(elapsed, std::chrono::milliseconds(240 + 30)) << "the ramp and the settle time are both waited for";
  EXPECT_DOUBLE_EQ(d.level("dimmer"), 1.0);
  EXPECT_THROW(run(io_, d.set_level("dimmer", 1.5)), Error);
}

TEST_F(EnttecDmxSimTest, SilentWidgetIsATypedTimeoutNotAHang) {
  sim::LinkFaults f;
  f.silent = true;
  sim_->set_faults(f);
  EnttecDmx d(io_.get_executor(), options());
  try {
    run(io_, d.connect(), std::chrono::seconds(5));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::timeout);
    EXPECT_FALSE(e.info().transcript.empty());
  }
}

TEST_F(EnttecDmxSimTest, GarbledRepliesAreRetried) {
  sim::LinkFaults f;
  f.garble_probability = 0.5;
  sim_->set_faults(f);
  auto o = options();
  o.attempts = 8;
  EnttecDmx d(io_.get_executor(), o);
  run(io_, d.connect());
  EXPECT_EQ(d.widget_serial(), 0x12345678u);
}

TEST_F(EnttecDmxSimTest, NonWidgetPortIsRefused) {
  auto o = options();
  o.port = "/dev/null";
  EnttecDmx d(io_.get_executor(), o);
  EXPECT_THROW(run(io_, d.connect(), std::chrono::seconds(5)), Error);
}

TEST_F(EnttecDmxSimTest, FactoryBuildsItFromTheSimulatorsAnnouncement) {
  // The shape colorlab-sim announces: one channel map with the dimmer in it.
  nlohmann::json channels = nlohmann::json::object();
  for (const auto& m : sim_->config().channels) channels[m.target] = m.channel;
  auto inst = drivers::make_instrument(io_.get_executor(),
                                       drivers::InstrumentConfig{"dmx", "dmx", sim_->port_path(), true, {{"channels", channels}}});
  run(io_, inst->connect());
  auto* lamps = dynamic_cast<drivers::LampController*>(inst.get());
  auto* dimmer = dynamic_cast<drivers::Dimmer*>(inst.get());
  ASSERT_NE(lamps, nullptr);
  ASSERT_NE(dimmer, nullptr);
  run(io_, lamps->set_lamps({"CWF"}));
  run(io_, dimmer->set_level("dimmer", 0.5));
  settle(io_, std::chrono::milliseconds(20));
  EXPECT_TRUE(scene_->lamp_on(sim::Lamp::cwf));
  EXPECT_GT(scene_->dimmer(), 45.0);
  EXPECT_LT(scene_->dimmer(), 55.0);
}

TEST(EnttecDmxOptionsTest, BadChannelMapsAreRefused) {
  boost::asio::io_context io;
  drivers::EnttecDmxOptions o;
  o.lamps = drivers::LampMap({{"D65", 1}}, 512, false);
  o.dimmer_channel = 1;
  EXPECT_THROW(EnttecDmx(io.get_executor(), o), Error);
  o.dimmer_channel = 0;
  o.slots = 4;
  o.lamps = drivers::LampMap({{"D65", 5}}, 512, false);
  EXPECT_THROW(EnttecDmx(io.get_executor(), o), Error);
}

}  // namespace
}  // namespace colorlab::test
