// The LS-110 driver against the meter simulator: ER10 becomes a typed misread with its hint, a
// silent meter becomes needs_operator with the hold-F hint within the configured timeout, and a
// garbled reply is measured again.
#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/ls110.hpp"
#include "colorlab/sim/ls110_sim.hpp"
#include "run_support.hpp"

namespace colorlab::test {
namespace {

class Ls110SimTest : public ::testing::Test {
 protected:
  static constexpr double kTruth = 245.3;
  void SetUp() override {
    sim_ = std::make_shared<sim::Ls110Sim>(
        io_.get_executor(), [] { return sim::Ls110Truth{kTruth, 0.0}; }, 5, 50.0);
    sim_->start();
  }
  void TearDown() override {
    sim_->stop();
    settle(io_, std::chrono::milliseconds(5));
  }
  drivers::Ls110Options options() const {
    drivers::Ls110Options o;
    o.port = sim_->port_path();
    o.simulated = true;
    o.reply_timeout = std::chrono::milliseconds(300);
    o.attempts = 3;
    return o;
  }
  boost::asio::io_context io_;
  std::shared_ptr<sim::Ls110Sim> sim_;
};

TEST_F(Ls110SimTest, MeasuresTheSimulatedLuminance) {
  drivers::Ls110 m(io_.get_executor(), options());
  run(io_, m.connect());
  auto r = run(io_, m.measure_luminance());
  EXPECT_NEAR(r.luminance, kTruth, 0.01);
  EXPECT_EQ(m.state(), drivers::InstrumentState::ready);
}

TEST_F(Ls110SimTest, Er10IsMisreadWithHint) {
  drivers::Ls110 m(io_.get_executor(), options());
  run(io_, m.connect());
  sim::Ls110Faults f;
  f.error_code = "ER10";
  f.error_once = true;
  sim_->set_faults(f);
  try {
    run(io_, m.measure_luminance());
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::misread);
    EXPECT_EQ(e.info().device_code, "ER10");
    EXPECT_FALSE(e.hint().empty());
    EXPECT_FALSE(e.info().transcript.empty());
  }
  // The meter itself is fine: the next reading works.
  EXPECT_NEAR(run(io_, m.measure_luminance()).luminance, kTruth, 0.01);
}

TEST_F(Ls110SimTest, SilentMeterNeedsOperatorWithinTheConfiguredTimeout) {
  drivers::Ls110 m(io_.get_executor(), options());
  run(io_, m.connect());
  sim::Ls110Faults f;
  f.silent = true;
  sim_->set_faults(f);
  auto t0 = std::chrono::steady_clock::now();
  try {
    run(io_, m.measure_luminance(), std::chrono::seconds(10));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::needs_operator);
    EXPECT_NE(e.hint().find("holding F"), std::string::npos) << e.hint();
  }
  // 3 attempts × 300 ms, plus scheduling slack; never the 5 s default or a hang.
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(3));
  EXPECT_EQ(m.state(), drivers::InstrumentState::needs_operator);
}

TEST_F(Ls110SimTest, GarbledReplyIsMeasuredAgain) {
  drivers::Ls110 m(io_.get_executor(), options());
  run(io_, m.connect());
  sim::Ls110Faults f;
  f.garble_probability = 0.5;
  sim_->set_faults(f);
  int ok = 0;
  for (int i = 0; i < 10; ++i) {
    try {
      auto r = run(io_, m.measure_luminance());
      EXPECT_NEAR(r.luminance, kTruth, 0.01) << "a garbled value must never be returned as a reading";
      ++ok;
    } catch (const Error& e) {
      EXPECT_TRUE(e.cls() == ErrorClass::coms_fail || e.cls() == ErrorClass::protocol_error) << e.what();
    }
  }
  EXPECT_GE(ok, 7);
}

}  // namespace
}  // namespace colorlab::test
