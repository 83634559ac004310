// The simulated serial instruments seen from a client on their ptys, through colorlab-sim: speed
// negotiation, every fault kind, the DMX widget driving the scene, and same seed -> same bytes.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "colorlab/wire/enttec_dmx_protocol.hpp"
#include "colorlab/wire/spectrolino_protocol.hpp"
#include "sim_process.hpp"

namespace sp = colorlab::wire::spectrolino;
namespace en = colorlab::wire::enttec;
using colorlab::test::SerialClient;
using colorlab::test::SimProcess;
using nlohmann::json;

namespace {

// time_scale 10: device times shrink tenfold, so a measurement takes 0.15 s of real time.
const char* kLab = R"(
time_scale = 10.0
[spectrolino]
table = false
[dmx]
serial = 12345678
[genicam]
enabled = false
)";

void sleep_s(double s) { std::this_thread::sleep_for(std::chrono::duration<double>(s)); }

std::string bytes(const std::vector<std::uint8_t>& v) { return std::string(v.begin(), v.end()); }

double measure_y(SerialClient& c) {
  EXPECT_EQ(c.transact(";20\r\n"), ":2500\r\n");
  auto xyz = sp::CParameterAnswer::decode(sp::unframe_answer(c.transact(";BA0904\r\n")));
  return xyz.values[1];
}

}  // namespace

TEST(SimSerialPty, SpectrolinoAnswersOnlyAtItsSpeedAndFollowsSpeedChanges) {
  SimProcess sim(kLab);
  SerialClient c(sim.port("spectrolino"), 19200);
  EXPECT_EQ(c.transact(";00\r\n", 0.3), "");  // the device listens at 9600
  c.set_speed(9600);
  EXPECT_EQ(c.transact(";00\r\n"), ":0B0101030001\r\n");
  EXPECT_EQ(c.transact(";4DCF\r\n"), ":1F0000\r\n");
  EXPECT_EQ(c.transact(";4D28\r\n"), ":1F0000\r\n");  // to 19200, answered at 9600
  EXPECT_EQ(c.transact(";00\r\n", 0.3), "");
  c.set_speed(19200, true);
  EXPECT_EQ(c.transact(";00\r\n"), ":0B0101030001\r\n");
  // Noise before a record (another program's probe) is discarded at the start character.
  EXPECT_EQ(c.transact("*idn?\r;00\r\n"), ":0B0101030001\r\n");
  auto truth = sim.control({{"cmd", "truth"}});
  EXPECT_EQ(truth["spectrolino"]["baud"], 19200);
  EXPECT_GE(truth["spectrolino"]["lines_ignored"].get<int>(), 2);
}

TEST(SimSerialPty, SpectrolinoLinkFaults) {
  SimProcess sim(kLab);
  SerialClient c(sim.port("spectrolino"), 9600);
  auto fault = [&](json f) {
    auto r = sim.control({{"cmd", "fault"}, {"instrument", "spectrolino"}, {"faults", f}});
    ASSERT_TRUE(r["ok"].get<bool>()) << r.dump();
  };
  fault({{"drop_probability", 1.0}});
  EXPECT_EQ(c.transact(";00\r\n", 0.3), "");
  fault({{"drop_probability", 0.0}, {"garble_probability", 1.0}});
  std::string garbled = c.transact(";00\r\n");
  ASSERT_EQ(garbled.size(), 15u);
  EXPECT_EQ(garbled.substr(garbled.size() - 2), "\r\n");
  try {
    sp::ParameterAnswer::decode(sp::unframe_answer(garbled));
    ADD_FAILURE() << "garbled answer decoded: " << garbled;
  } catch (const colorlab::Error& e) {
    EXPECT_EQ(e.cls(), colorlab::ErrorClass::coms_fail);
  }
  fault({{"garble_probability", 0.0}, {"partial_probability", 1.0}});
  std::string partial = c.transact(";00\r\n", 0.3);
  EXPECT_EQ(partial, std::string(":0B0101030001\r\n").substr(0, 7));
  fault({{"partial_probability", 0.0}, {"extra_latency_s", 3.0}});  // 0.3 s real at time scale 10
  auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(c.transact(";00\r\n"), ":0B0101030001\r\n");
  EXPECT_GE(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 0.3);
  fault({{"extra_latency_s", 0.0}, {"silent", true}});
  EXPECT_EQ(c.transact(";00\r\n", 0.3), "");
  fault({{"silent", false}});
  EXPECT_EQ(c.transact(";00\r\n"), ":0B0101030001\r\n");
  fault({{"disconnect_s", 5.0}});  // 0.5 s real
  EXPECT_EQ(c.transact(";00\r\n", 0.2), "");
  sleep_s(0.5);
  EXPECT_EQ(c.transact(";00\r\n"), ":0B0101030001\r\n");
}

TEST(SimSerialPty, SpectrolinoDeviceFaults) {
  SimProcess sim(kLab);
  SerialClient c(sim.port("spectrolino"), 9600);
  auto fault = [&](json f) {
    auto r = sim.control({{"cmd", "fault"}, {"instrument", "spectrolino"}, {"faults", f}});
    ASSERT_TRUE(r["ok"].get<bool>()) << r.dump();
  };
  // A stand-alone Spectrolino starts on its tile.
  fault({{"exec_error", "lamp_failure"}, {"exec_error_once", true}});
  EXPECT_EQ(c.transact(";220907\r\n"), ":2504\r\n");
  EXPECT_EQ(c.transact(";220907\r\n"), ":2513\r\n");
  fault({{"exec_error", "measuring_disabled"}, {"exec_error_once", false}});
  EXPECT_EQ(c.transact(";20\r\n"), ":2509\r\n");
  fault({{"exec_error", nullptr}});
  EXPECT_EQ(c.transact(";20\r\n"), ":2500\r\n");
  fault({{"expire_calibration", true}});
  EXPECT_EQ(c.transact(";20\r\n"), ":2537\r\n");
  EXPECT_EQ(c.transact(";220907\r\n"), ":2513\r\n");
  fault({{"calibration_lifetime_s", 2.0}});  // 0.2 s real
  EXPECT_EQ(c.transact(";20\r\n"), ":2500\r\n");
  sleep_s(0.3);
  EXPECT_EQ(c.transact(";20\r\n"), ":2537\r\n");
  // Power cycle: back at the power-on speed with no calibration.
  EXPECT_EQ(c.transact(";4D28\r\n"), ":1F0000\r\n");
  c.set_speed(19200);
  EXPECT_EQ(c.transact(";00\r\n"), ":0B0101030001\r\n");
  fault({{"power_cycle", true}});
  EXPECT_EQ(c.transact(";00\r\n", 0.3), "");
  c.set_speed(9600);
  EXPECT_EQ(c.transact(";00\r\n"), ":0B0101030001\r\n");
  EXPECT_EQ(sim.control({{"cmd", "fault"}, {"instrument", "spectrolino"}, {"faults", {{"exec_error", "bogus"}}}})["ok"],
            false);
}

TEST(SimSerialPty, LampDropoutSeenInEmission) {
  SimProcess sim(kLab);
  SerialClient c(sim.port("spectrolino"), 9600);
  EXPECT_EQ(c.transact(";4D9D\r\n"), ":1F0000\r\n");
  EXPECT_EQ(c.transact(";220908\r\n"), ":2534\r\n");
  double lit = measure_y(c);
  EXPECT_GT(lit, 100.0);  // D65 cabinet at full dimmer: hundreds of lux
  auto r = sim.control({{"cmd", "fault"}, {"instrument", "cabinet"}, {"faults", {{"lamp_dropout", {{"lamp", "D65"}, {"seconds", 10.0}}}}}});
  ASSERT_TRUE(r["ok"].get<bool>()) << r.dump();
  EXPECT_LT(measure_y(c), 0.01 * lit);
  sleep_s(1.2);
  EXPECT_GT(measure_y(c), 0.8 * lit);  // relit, still warming up
}

TEST(SimSerialPty, LampDriftThroughTheControlChannelWithItsTruth) {
  SimProcess sim(kLab);
  const double before = sim.control({{"cmd", "truth"}})["ls110"]["luminance"].get<double>();
  // −30 %/min for 10 simulated seconds (1 s real at time scale 10), then back at the same rate.
  auto r = sim.control({
      {"cmd", "fault"},
      {"instrument", "cabinet"},
      {"faults", {{"lamp_drift", {{"lamp", "D65"}, {"rate_pct_per_min", -30}, {"seconds", 10}, {"then", "return"}}}}},
  });
  ASSERT_TRUE(r["ok"].get<bool>()) << r.dump();
  EXPECT_EQ(r["lamp_drift"]["then"], "return");
  sleep_s(1.5);  // 15 simulated seconds: 5 % down at 10 s, 2.5 % down now
  auto t = sim.control({{"cmd", "truth"}});
  const double factor = t["drift"]["D65"]["factor"].get<double>();
  EXPECT_GT(factor, 0.95);
  EXPECT_LT(factor, 0.99);
  // Warm from the start: its output is the drift alone (read a few microseconds apart: 0.5 %/s moves 1e-6 in 0.2 ms).
  EXPECT_NEAR(t["output"]["D65"].get<double>(), factor, 1e-5);
  EXPECT_NEAR(t["ls110"]["luminance"].get<double>(), before * factor, 1e-3 * before);
  sleep_s(1.0);  // past 20 simulated seconds: normal again
  t = sim.control({{"cmd", "truth"}});
  EXPECT_DOUBLE_EQ(t["drift"]["D65"]["factor"].get<double>(), 1.0);
  EXPECT_NEAR(t["ls110"]["luminance"].get<double>(), before, 1e-9 * before);
  EXPECT_FALSE(sim.control({{"cmd", "fault"}, {"instrument", "cabinet"}, {"faults", {{"lamp_drift", {{"lamp", "D65"}, {"then", "later"}}}}}})["ok"].get<bool>());
  EXPECT_FALSE(sim.control({{"cmd", "fault"}, {"instrument", "cabinet"}, {"faults", {{"lamp_flicker", true}}}})["ok"].get<bool>());
}

TEST(SimSerialPty, DmxWidgetDrivesTheScene) {
  SimProcess sim(kLab);
  SerialClient c(sim.port("dmx"), 115200);
  c.write(bytes(en::get_serial_request()));
  EXPECT_EQ(c.read_n(9, 2.0), bytes(en::encode_frame(10, std::vector<std::uint8_t>{0x78, 0x56, 0x34, 0x12})));
  c.write(bytes(en::get_parameters_request()));
  EXPECT_EQ(c.read_n(10, 2.0), bytes({0x7E, 0x03, 0x05, 0x00, 0x2C, 0x01, 0x09, 0x01, 0x28, 0xE7}));
  c.write(bytes(en::set_parameters_request({0, 20, 4, 30, {}})));
  c.write(bytes(en::get_parameters_request()));
  EXPECT_EQ(c.read_n(10, 2.0), bytes({0x7E, 0x03, 0x05, 0x00, 0x2C, 0x01, 20, 4, 30, 0xE7}));
  c.write(bytes(en::encode_frame(77, {})));  // OLA extension: a genuine widget stays silent
  EXPECT_EQ(c.read_n(1, 0.2), "");
  std::vector<std::uint8_t> slots(512, 0);
  slots[1] = 255;  // TL84
  slots[5] = 128;  // dimmer ~50 %
  c.write(bytes(en::send_dmx_request(slots)));
  c.write(bytes({0x7E, 0x06, 0x01, 0x00, 0x00, 0x00}));  // bad end byte: dropped
  c.write(bytes(en::get_serial_request()));
  EXPECT_EQ(c.read_n(9, 2.0).size(), 9u);  // everything before it has been processed
  auto t = sim.control({{"cmd", "truth"}});
  EXPECT_EQ(t["lamps_on"], json::array({"TL84"}));
  EXPECT_NEAR(t["dimmer"].get<double>(), 128 * 100.0 / 255, 1e-9);
  EXPECT_EQ(t["dmx"]["packets"], 1);
  EXPECT_EQ(t["dmx"]["bad_frames"], 1);
  auto f = sim.control({{"cmd", "fault"}, {"instrument", "dmx"}, {"faults", {{"drop_probability", 1.0}}}});
  ASSERT_TRUE(f["ok"].get<bool>());
  c.write(bytes(en::get_serial_request()));
  EXPECT_EQ(c.read_n(1, 0.2), "");
}

TEST(SimSerialPty, SameSeedSameBytes) {
  auto session = [](std::uint64_t seed) {
    SimProcess sim(kLab, seed);
    SerialClient c(sim.port("spectrolino"), 9600);
    std::string all = c.transact(";220907\r\n");
    sim.control({{"cmd", "place"}, {"target", "patch"}, {"patch", "E5"}});
    for (int i = 0; i < 2; ++i) {
      all += c.transact(";20\r\n");
      all += c.transact(";B80900\r\n");
    }
    return all;
  };
  std::string a = session(21);
  EXPECT_EQ(a, session(21));
  EXPECT_NE(a, session(22));
}

TEST(SimSerialPty, Ls110StillAnswers) {
  SimProcess sim(kLab);
  SerialClient c(sim.port("ls110"), 4800);
  std::string r = c.transact("MES\r\n", 3.0);
  EXPECT_EQ(r.substr(0, 5), "OK00,") << r;
}
