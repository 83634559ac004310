// The Spectrolino driver against the SpectroScan T / stand-alone simulator on a pty: negotiation,
// identity, calibration, spectra checked against the Scene's chart truth, the serpentine chart read
// with its recalibration schedule, and every fault the simulator can inject.
#include <cmath>

#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/drivers/factory.hpp"
#include "spectrolino_sim_fixture.hpp"

namespace colorlab::test {
namespace {

using drivers::Spectrolino;
using drivers::SpectrolinoTopology;

double max_abs_diff(const std::vector<double>& a, const sim::Spectrum& truth) {
  double worst = 0;
  for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, std::abs(a[i] - truth.values[i]));
  return worst;
}

TEST_F(SpectrolinoSimTest, ConnectsToTableAtFastestSpeedWithHardwareHandshake) {
  start(true);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  EXPECT_EQ(s.topology(), SpectrolinoTopology::spectroscan_t);
  EXPECT_EQ(s.baud(), 57600u);
  auto line = sim_->client_settings();
  EXPECT_EQ(line.baud, 57600u);
  EXPECT_TRUE(line.rts_cts);
  EXPECT_EQ(sim_->model().baud(), 57600);
  auto id = s.identity();
  EXPECT_EQ(id.serial, "12345/table:54321");
  EXPECT_NE(id.model.find("SpectroScan T"), std::string::npos) << id.model;
  EXPECT_EQ(s.state(), drivers::InstrumentState::needs_calibration);
}

TEST_F(SpectrolinoSimTest, ConnectsToStandaloneSpectrolino) {
  start(false);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  EXPECT_EQ(s.topology(), SpectrolinoTopology::standalone);
  EXPECT_EQ(s.baud(), 57600u);
  EXPECT_TRUE(sim_->client_settings().rts_cts);
  EXPECT_EQ(s.identity().serial, "12345");
  EXPECT_EQ(s.identity().model.rfind("Spectrolino", 0), 0u);
  // Table operations are refused with a typed error, not sent.
  try {
    run(io_, s.home());
    FAIL() << "home() on a stand-alone Spectrolino must throw";
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::unsupported);
  }
}

TEST_F(SpectrolinoSimTest, FactoryBuildsItFromTheSimulatorsAnnouncement) {
  start(true);
  auto inst = drivers::make_instrument(
      io_.get_executor(), drivers::InstrumentConfig{
                              "spectro",
                              "spectrolino",
                              sim_->port_path(),
                              true,
                              {{"power_on_baud", 9600}, {"table", true}, {"command_timeout_ms", 600}},
                          });
  run(io_, inst->connect());
  EXPECT_EQ(inst->identity().serial, "12345/table:54321");
  auto caps = inst->capabilities();
  EXPECT_NE(std::find(caps.begin(), caps.end(), drivers::Capability::xy_table), caps.end());
  ASSERT_NE(dynamic_cast<drivers::XyTable*>(inst.get()), nullptr);
  ASSERT_NE(dynamic_cast<drivers::Spectrometer*>(inst.get()), nullptr);
}

TEST_F(SpectrolinoSimTest, ReconnectFindsDeviceStillAtNegotiatedSpeed) {
  start(true);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  s.disconnect();
  auto before = sim_->lines_answered();
  run(io_, s.connect());
  EXPECT_EQ(s.baud(), 57600u);
  EXPECT_GT(sim_->lines_answered(), before);
}

TEST_F(SpectrolinoSimTest, MoveAndMeasureMatchesChartTruthAndXyzIsComputedLocally) {
  start(true);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  EXPECT_THROW(run(io_, s.move_and_measure(100, 100)), Error);  // not calibrated yet
  run(io_, s.calibrate());
  EXPECT_EQ(s.state(), drivers::InstrumentState::ready);
  auto layout = chart_layout();
  const int patch = 37;  // D8
  int strip = patch / layout.patches_per_strip, k = patch % layout.patches_per_strip;
  double x = layout.origin_x_mm + k * layout.step_x_mm + strip * layout.pass_x_mm;
  double y = layout.origin_y_mm + k * layout.step_y_mm + strip * layout.pass_y_mm;
  auto before = sim_->lines_answered();
  auto r = run(io_, s.move_and_measure(x, y));
  EXPECT_EQ(sim_->lines_answered() - before, 1u) << "one command per patch: XYZ must not be queried";
  const auto& truth = scene_->chart().patches[patch].reflectance;
  ASSERT_EQ(r.values.size(), 36u);
  EXPECT_LT(max_abs_diff(r.values, truth), 0.02);
  ASSERT_TRUE(r.xyz.has_value());
  // Truth XYZ: the chart's true reflectance integrated independently of the driver's reading.
  auto d50 = analysis::load_illuminant("D50");
  auto obs = analysis::load_observer(analysis::Observer::cie1931_2deg);
  analysis::ReflectanceIntegrator integ(d50, obs, analysis::uniform_grid(380, 730, 10));
  Eigen::RowVectorXd t(36);
  for (int i = 0; i < 36; ++i) t[i] = truth.values[static_cast<std::size_t>(i)];
  auto xyz = integ.xyz(t);
  EXPECT_NEAR((*r.xyz)[1], xyz.Y, 1.0);
  EXPECT_NEAR((*r.xyz)[0], xyz.X, 1.0);
  EXPECT_NEAR((*r.xyz)[2], xyz.Z, 1.0);
  auto pos = run(io_, s.position());
  EXPECT_NEAR(pos.x_mm, x, 0.1);
  EXPECT_NEAR(pos.y_mm, y, 0.1);
  EXPECT_FALSE(pos.head_down);
}

TEST_F(SpectrolinoSimTest, TableCommandsMoveTheSimulatedHead) {
  start(true);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  run(io_, s.move_to(120.5, 80.2));
  auto [x, y] = sim_->model().head_mm();
  EXPECT_NEAR(x, 120.5, 0.05);
  EXPECT_NEAR(y, 80.2, 0.05);
  run(io_, s.head_down());
  EXPECT_TRUE(run(io_, s.position()).head_down);
  run(io_, s.head_up());
  run(io_, s.hold_paper(true));
  EXPECT_TRUE(run(io_, s.table_status()).paper_held);
  run(io_, s.hold_paper(false));
  EXPECT_FALSE(run(io_, s.table_status()).paper_held);
  run(io_, s.home());
  auto home = sim_->model().head_mm();
  EXPECT_NEAR(home.first, 0, 0.05);
  EXPECT_NEAR(home.second, 0, 0.05);
  try {
    run(io_, s.move_to(400, 10));
    FAIL() << "a move off the table must be refused";
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::bad_parameter);
  }
}

TEST_F(SpectrolinoSimTest, ChartReadIsSerpentineWithRecalibrationAtRowStarts) {
  start(true);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  int progress_calls = 0;
  auto readings = run(io_, s.read_chart(chart_layout(), [&](int, int total) {
    ++progress_calls;
    EXPECT_EQ(total, 140);
    // 14 patches per row, 50 readings per calibration: never more than 50 since the last one.
    EXPECT_LE(s.readings_since_calibration(), 50);
  }));
  EXPECT_EQ(progress_calls, 140);
  ASSERT_EQ(readings.size(), 140u);
  // Rows of 14: calibrate before rows 1, 4, 7, 10 (42 + 14 would pass 50).
  EXPECT_EQ(s.calibrations_done(), 4);
  double worst = 0;
  for (std::size_t i = 0; i < 140; ++i) {
    worst = std::max(worst, max_abs_diff(readings[i].values, scene_->chart().patches[i].reflectance));
    EXPECT_EQ(readings[i].attempts, 1);
  }
  EXPECT_LT(worst, 0.03);
}

TEST_F(SpectrolinoSimTest, EmissionModeMeasuresTheCabinetLight) {
  start(true);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  run(io_, s.set_mode(drivers::SpectralMode::emission));
  EXPECT_EQ(s.state(), drivers::InstrumentState::needs_calibration);
  run(io_, s.calibrate());
  auto r = run(io_, s.measure());
  EXPECT_EQ(r.mode, drivers::SpectralMode::emission);
  auto truth = sim_->model().true_reflectance();  // in emission mode: the irradiance the head sees
  int checked = 0;
  for (std::size_t i = 4; i < 32; ++i) {
    if (truth[i] > 1.0f) {
      EXPECT_NEAR(r.values[i] / truth[i], 1.0, 0.02) << "band " << i;
      ++checked;
    }
  }
  EXPECT_GT(checked, 20) << "the D65 lamp must light the cabinet";
  ASSERT_TRUE(r.xyz.has_value());
  EXPECT_GT((*r.xyz)[1], 0.0);
}

TEST_F(SpectrolinoSimTest, TransmissionOnSpectroScanT) {
  start(true);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  run(io_, s.set_mode(drivers::SpectralMode::transmission));
  run(io_, s.calibrate());
  auto r = run(io_, s.measure());
  EXPECT_LT(max_abs_diff(r.values, scene_->transmission_sample()), 0.02);
  EXPECT_EQ(s.calibration().front().readings_left, 9) << "transmission recalibrates every 10 readings";
  run(io_, s.set_mode(drivers::SpectralMode::reflectance));
  EXPECT_FALSE(s.calibration().front().valid);
}

TEST_F(SpectrolinoSimTest, TransmissionNeedsTheTTable) {
  start(false);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  try {
    run(io_, s.set_mode(drivers::SpectralMode::transmission));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::unsupported);
  }
}

TEST_F(SpectrolinoSimTest, StandaloneMeasureReadsWhatIsUnderTheInstrument) {
  start(false);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  sim_->model().place_on_tile();
  run(io_, s.calibrate());
  sim_->model().place_on_patch(12);
  auto r = run(io_, s.measure());
  EXPECT_LT(max_abs_diff(r.values, scene_->chart().patches[12].reflectance), 0.02);
  EXPECT_EQ(s.readings_since_calibration(), 1);
}

// ---------------------------------------------------------------- faults

TEST_F(SpectrolinoSimTest, LampFailureIsTypedHardwareError) {
  start(true);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  sim::SpectrolinoFaults f;
  f.exec_error = 0x04;
  sim_->set_faults(f);
  try {
    run(io_, s.calibrate());
    FAIL() << "calibration with a failed lamp must throw";
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::hardware_fail);
    EXPECT_EQ(e.info().device_code, "spectrolino:04");
    EXPECT_FALSE(e.hint().empty());
    EXPECT_FALSE(e.info().transcript.empty());
  }
  EXPECT_EQ(s.state(), drivers::InstrumentState::fault);
}

TEST_F(SpectrolinoSimTest, EveryErrorTypeCodeIsTypedWithDeviceCodeAndHint) {
  start(true);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  const std::vector<std::uint8_t> codes{0x01, 0x02, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0A, 0x0D, 0x0E,
                                        0x10, 0x11, 0x15, 0x32, 0x33, 0x35, 0x36, 0x37, 0x38, 0x3C};
  for (auto code : codes) {
    sim::SpectrolinoFaults f;
    f.exec_error = code;
    f.exec_error_once = true;
    sim_->set_faults(f);
    const std::string hex = wire::spectrolino::to_hex(std::vector<std::uint8_t>{code});
    try {
      run(io_, s.calibrate());
      ADD_FAILURE() << "error type " << hex << " was taken for success";
    } catch (const Error& e) {
      EXPECT_EQ(e.info().device_code, "spectrolino:" + hex);
      // Notify codes (reset done) have no error class of their own: out of place, they are a protocol error.
      auto expected = wire::spectrolino::describe_exec_error(code).cls;
      if (expected == ErrorClass::internal) expected = ErrorClass::protocol_error;
      EXPECT_EQ(e.cls(), expected) << hex << ": " << e.what();
      EXPECT_FALSE(e.hint().empty()) << hex;
    }
  }
  // Nothing is left broken: the next calibration works.
  run(io_, s.calibrate());
  EXPECT_EQ(s.state(), drivers::InstrumentState::ready);
}

TEST_F(SpectrolinoSimTest, WrongWhiteOnStandaloneAsksForTheOperator) {
  start(false);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  sim::SpectrolinoFaults f;
  f.exec_error = 0x0E;  // too much light / wrong white
  f.exec_error_once = true;
  sim_->set_faults(f);
  try {
    run(io_, s.calibrate());
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::needs_operator);
    EXPECT_NE(e.hint().find("white"), std::string::npos);
  }
  EXPECT_EQ(s.state(), drivers::InstrumentState::needs_operator);
}

TEST_F(SpectrolinoSimTest, MisreadDuringChartIsRetriedAfterRecalibration) {
  start(true);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  run(io_, s.calibrate());
  int cals = s.calibrations_done();
  sim::SpectrolinoFaults f;
  f.exec_error = 0x09;  // measuring disabled: a misread
  f.exec_error_once = true;
  sim_->set_faults(f);
  drivers::ChartLayout one = chart_layout();
  one.strips = 1;
  one.patches_per_strip = 3;
  auto readings = run(io_, s.read_chart(one));
  ASSERT_EQ(readings.size(), 3u);
  EXPECT_EQ(readings[0].attempts, 2);
  EXPECT_EQ(readings[1].attempts, 1);
  EXPECT_EQ(s.calibrations_done(), cals + 1) << "a failed patch forces a recalibration";
  EXPECT_LT(max_abs_diff(readings[0].values, scene_->chart().patches[0].reflectance), 0.02);
}

TEST_F(SpectrolinoSimTest, PersistentMisreadGivesUpAfterFiveTries) {
  start(true);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  run(io_, s.calibrate());
  sim::SpectrolinoFaults f;
  f.exec_error = 0x09;
  sim_->set_faults(f);
  drivers::ChartLayout one = chart_layout();
  one.strips = 1;
  one.patches_per_strip = 1;
  try {
    run(io_, s.read_chart(one));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::misread);
    EXPECT_NE(std::string(e.what()).find("5 times"), std::string::npos) << e.what();
  }
}

TEST_F(SpectrolinoSimTest, ExpiredCalibrationIsDetectedAndRenewedDuringChart) {
  start(true);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  run(io_, s.calibrate());
  int cals = s.calibrations_done();
  sim::SpectrolinoFaults f;
  f.expire_calibration = true;
  sim_->set_faults(f);
  drivers::ChartLayout one = chart_layout();
  one.strips = 1;
  one.patches_per_strip = 2;
  auto readings = run(io_, s.read_chart(one));
  EXPECT_EQ(readings[0].attempts, 2);
  EXPECT_EQ(s.calibrations_done(), cals + 1);
}

TEST_F(SpectrolinoSimTest, GarbledAndDroppedRepliesAreRetried) {
  start(true);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  sim::SpectrolinoFaults f;
  f.link.garble_probability = 0.3;
  f.link.drop_probability = 0.1;
  sim_->set_faults(f);
  auto o = options();
  int ok = 0;
  for (int i = 0; i < 10; ++i) {
    try {
      run(io_, s.table_status());
      ++ok;
    } catch (const Error& e) {
      // Three bad replies in a row can happen (p ≈ 0.06); it must then be a typed link error.
      EXPECT_TRUE(e.cls() == ErrorClass::coms_fail || e.cls() == ErrorClass::timeout) << e.what();
    }
  }
  EXPECT_GE(ok, 7);
}

TEST_F(SpectrolinoSimTest, PartialRepliesAreRetried) {
  start(true);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  sim::SpectrolinoFaults f;
  f.link.partial_probability = 0.3;
  sim_->set_faults(f);
  int ok = 0;
  for (int i = 0; i < 6; ++i) {
    try {
      run(io_, s.table_status());
      ++ok;
    } catch (const Error& e) {
      EXPECT_TRUE(e.cls() == ErrorClass::coms_fail || e.cls() == ErrorClass::timeout) << e.what();
    }
  }
  EXPECT_GE(ok, 4);
}

TEST_F(SpectrolinoSimTest, ExtraLatencyWithinTheDeadlineIsTolerated) {
  start(true);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  sim::SpectrolinoFaults f;
  f.link.extra_latency_s = 0.3 * kTimeScale;  // 0.3 s real, under the 0.6 s command timeout
  f.link.jitter_s = 0.05 * kTimeScale;
  sim_->set_faults(f);
  auto st = run(io_, s.table_status());
  EXPECT_TRUE(st.online);
}

TEST_F(SpectrolinoSimTest, ShortCableDropIsBridgedByRetries) {
  start(true);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  sim::SpectrolinoFaults f;
  f.link.disconnect_s = 1.0 * kTimeScale;  // 1 s real: the first attempts time out, the third answers
  sim_->set_faults(f);
  auto st = run(io_, s.table_status());
  EXPECT_TRUE(st.online);
  EXPECT_EQ(s.state(), drivers::InstrumentState::needs_calibration) << "a bridged drop changes nothing";
}

TEST_F(SpectrolinoSimTest, SilentDeviceTimesOutWithoutHanging) {
  start(true);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  sim::SpectrolinoFaults f;
  f.link.silent = true;
  sim_->set_faults(f);
  auto t0 = std::chrono::steady_clock::now();
  try {
    run(io_, s.table_status());
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::timeout);
    EXPECT_FALSE(e.info().transcript.empty());
  }
  // 3 attempts × 0.6 s command timeout, nothing more.
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(4));
  EXPECT_EQ(s.state(), drivers::InstrumentState::fault);
}

TEST_F(SpectrolinoSimTest, PowerCycleIsRecoveredByReconnect) {
  start(true);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  run(io_, s.calibrate());
  sim::SpectrolinoFaults f;
  f.power_cycle = true;
  sim_->set_faults(f);
  // The device is back at its power-on speed: the driver's next command times out...
  EXPECT_THROW(run(io_, s.table_status()), Error);
  // ...and the reconnect state machine scans, renegotiates and re-verifies identity.
  drivers::Reconnector rc(io_.get_executor(), options().reconnect);
  run(io_, rc.reconnect(s));
  EXPECT_EQ(rc.phase(), drivers::ReconnectPhase::connected);
  EXPECT_EQ(s.baud(), 57600u);
  EXPECT_EQ(s.state(), drivers::InstrumentState::needs_calibration) << "a power cycle loses the white calibration";
  run(io_, s.calibrate());
  EXPECT_EQ(s.state(), drivers::InstrumentState::ready);
}

TEST_F(SpectrolinoSimTest, PowerCycleDuringChartIsReconnectedAndRecalibrated) {
  start(true);
  Spectrolino s(io_.get_executor(), options());
  run(io_, s.connect());
  run(io_, s.calibrate());
  int cals = s.calibrations_done();
  sim::SpectrolinoFaults f;
  f.power_cycle = true;
  sim_->set_faults(f);
  drivers::ChartLayout one = chart_layout();
  one.strips = 1;
  one.patches_per_strip = 3;
  auto readings = run(io_, s.read_chart(one));
  ASSERT_EQ(readings.size(), 3u);
  EXPECT_EQ(readings[0].attempts, 2);
  EXPECT_EQ(s.baud(), 57600u);
  EXPECT_EQ(s.calibrations_done(), cals + 1);
  EXPECT_LT(max_abs_diff(readings[2].values, scene_->chart().patches[2].reflectance), 0.02);
}

TEST_F(SpectrolinoSimTest, NoDeviceOnPortIsNoComms) {
  start(true);
  sim::SpectrolinoFaults f;
  f.link.silent = true;
  sim_->set_faults(f);
  Spectrolino s(io_.get_executor(), options());
  try {
    run(io_, s.connect());
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::no_comms);
    EXPECT_NE(std::string(e.what()).find("57600"), std::string::npos) << e.what();
  }
  EXPECT_EQ(s.state(), drivers::InstrumentState::disconnected);
}

}  // namespace
}  // namespace colorlab::test
