// Recorded-transcript tests: the exact bytes the Spectrolino driver exchanges per operation, against
// a scripted pty peer. Request lines are written out literally from instrument-protocols §1; long
// answers are built with the wire codec. Any unexpected byte leaves the driver unanswered and fails.
#include <gtest/gtest.h>

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/spectrolino.hpp"
#include "run_support.hpp"
#include "scripted_peer.hpp"

namespace colorlab::test {
namespace {

namespace sl = colorlab::wire::spectrolino;

std::string answer(const sl::Bytes& body) { return sl::frame_answer(body); }

std::string device_data() {
  sl::DeviceDataAnswer d;
  d.name = "Spectrolino";
  d.part_no = "36.62.00";
  d.serial = 12345;
  d.software = "V1.00";
  return answer(d.encode());
}

std::string target_id() {
  sl::TargetIdAnswer t;
  t.name = "Spectrolino";
  t.serial = 12345;
  t.year = 1999;
  return answer(t.encode());
}

std::string spectrum_answer(bool via_table) {
  sl::Spectrum s{};
  for (std::size_t i = 0; i < s.size(); ++i) s[i] = 0.2f + 0.01f * static_cast<float>(i);
  if (via_table) {
    sl::SpectrumAnswer a;
    a.spectrum = s;
    return answer(a.encode());
  }
  sl::SpecParameterAnswer a;
  a.spectrum = s;
  return answer(a.encode());
}

std::string table_type() {
  sl::TypeAnswer t;
  t.name = "SpectroScanT";
  return answer(t.encode());
}

const std::string ok1f = ":1F0000\r\n";
const std::string scan_ok = ":D18000\r\n";

drivers::SpectrolinoOptions options(const std::string& port) {
  drivers::SpectrolinoOptions o;
  o.port = port;
  o.timeouts.command = std::chrono::milliseconds(500);
  o.timeouts.measure = std::chrono::milliseconds(500);
  o.timeouts.move = std::chrono::milliseconds(500);
  o.timeouts.init = std::chrono::milliseconds(500);
  o.timeouts.probe = std::chrono::milliseconds(100);
  o.command_attempts = 1;
  return o;
}

class TranscriptTest : public ::testing::Test {
 protected:
  std::shared_ptr<ScriptedPeer> peer(std::vector<ScriptStep> steps) {
    peer_ = std::make_shared<ScriptedPeer>(io_, std::move(steps));
    peer_->start();
    return peer_;
  }
  void TearDown() override {
    if (peer_) {
      for (const auto& m : peer_->mismatches()) ADD_FAILURE() << m;
      peer_->stop();
    }
    settle(io_, std::chrono::milliseconds(5));
  }
  boost::asio::io_context io_;
  std::shared_ptr<ScriptedPeer> peer_;
};

TEST_F(TranscriptTest, StandaloneConnectCalibrateMeasure) {
  auto p = peer({
      // Baud scan: the 57600 probe goes unanswered (ignored at the wrong speed), then 9600 answers
      // with COM error 04: a stand-alone Spectrolino does not know the D0 record.
      {";D024\r\n", ":2604\r\n", 9600},
      {";4DCF\r\n", ok1f, 9600},  // hardware handshake
      {";4D99\r\n", ok1f, 9600},  // 57600
      {";00\r\n", ":0B0101030001\r\n", 57600, true},
      {";B5\r\n", device_data(), 57600},
      {";2B\r\n", target_id(), 57600},
      {";1601010300\r\n", ok1f},  // ANSI T, absolute white, D50, 2°
      {";4D9B\r\n", ok1f},        // reflectance
      // calibrate()
      {";220907\r\n", ":2513\r\n"},      // white calibration with warning → 13 WhiteMeasOK
      {";00\r\n", ":0B0101030001\r\n"},  // filter check
      // measure()
      {";20\r\n", ":2500\r\n"},
      {";B80900\r\n", spectrum_answer(false)},
  });
  drivers::Spectrolino s(io_.get_executor(), options(p->path()));
  run(io_, s.connect());
  EXPECT_EQ(p->position(), 8u);
  EXPECT_EQ(p->ignored(), 1u) << "exactly one probe at 57600 before 9600";
  run(io_, s.calibrate());
  auto r = run(io_, s.measure());
  EXPECT_TRUE(p->done());
  ASSERT_EQ(r.values.size(), 36u);
  EXPECT_NEAR(r.values[0], 0.2, 1e-6);
  EXPECT_NEAR(r.values[35], 0.55, 1e-6);
}

TEST_F(TranscriptTest, TableConnectAndMoveAndMeasure) {
  auto p = peer({
      {";D024\r\n", ":D18310\r\n", 9600},  // status: online → a SpectroScan
      {";D00A\r\n", scan_ok, 9600},        // InitializeDevice
      {";D010\r\n", scan_ok, 9600},        // online
      {";D02102\r\n", scan_ok, 9600},      // hardware handshake
      {";D0200A\r\n", scan_ok, 9600},      // 57600
      {";D024\r\n", ":D18310\r\n", 57600, true},
      {";D00B\r\n", scan_ok},  // find the Spectrolino
      {";D030\r\n", table_type()},
      {";B5\r\n", device_data()},
      {";2B\r\n", target_id()},
      {";D031\r\n", ":D19131D40000\r\n"},  // table serial 54321
      {";D034\r\n", answer(sl::SoftwareVersionAnswer{"V2.10"}.encode())},
      {";1601010300\r\n", ok1f},
      {";D00D00\r\n", scan_ok},  // SpectroScan T: table mode reflectance
      // calibrate(): tile 1, head down, white cal, head up, filter check
      {";D00600\r\n", scan_ok},
      {";D004\r\n", scan_ok},
      {";220907\r\n", ":2513\r\n"},
      {";D003\r\n", scan_ok},
      {";00\r\n", ":0B0101030001\r\n"},
      // move_and_measure(100.0, 50.0): x = 1000 = 03E8, y = 500 = 01F4, little-endian
      {";D007E803F401\r\n", spectrum_answer(true)},
  });
  drivers::Spectrolino s(io_.get_executor(), options(p->path()));
  run(io_, s.connect());
  EXPECT_EQ(s.topology(), drivers::SpectrolinoTopology::spectroscan_t);
  EXPECT_EQ(s.identity().serial, "12345/table:54321");
  run(io_, s.calibrate());
  auto r = run(io_, s.move_and_measure(100.0, 50.0));
  EXPECT_TRUE(p->done());
  EXPECT_NEAR(r.values[10], 0.3, 1e-6);
}

TEST_F(TranscriptTest, ScanErrorAnswerToMoveIsTyped) {
  auto p = peer({
      {";D024\r\n", ":D18310\r\n", 9600},
      {";D00A\r\n", scan_ok},
      {";D010\r\n", scan_ok},
      {";D02102\r\n", scan_ok},
      {";D0200A\r\n", scan_ok},
      {";D024\r\n", ":D18310\r\n", 57600},
      {";D00B\r\n", scan_ok},
      {";D030\r\n", table_type()},
      {";B5\r\n", device_data()},
      {";2B\r\n", target_id()},
      {";D031\r\n", ":D19131D40000\r\n"},
      {";D034\r\n", answer(sl::SoftwareVersionAnswer{"V2.10"}.encode())},
      {";1601010300\r\n", ok1f},
      {";D00D00\r\n", scan_ok},
      {";D000000001"
       "0A00\r\n",
       ":D18001\r\n"},  // move absolute: sensor, x 256 = 0100 → "0001", y 10 → "0A00"; device offline
  });
  drivers::Spectrolino s(io_.get_executor(), options(p->path()));
  run(io_, s.connect());
  try {
    run(io_, s.move_to(25.6, 1.0));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.info().device_code, "spectroscan:01");
    EXPECT_FALSE(e.info().transcript.empty());
  }
  EXPECT_TRUE(p->done());
}

std::vector<ScriptStep> table_connect_script() {
  return {
      {";D024\r\n", ":D18310\r\n", 9600},
      {";D00A\r\n", scan_ok},
      {";D010\r\n", scan_ok},
      {";D02102\r\n", scan_ok},
      {";D0200A\r\n", scan_ok},
      {";D024\r\n", ":D18310\r\n", 57600},
      {";D00B\r\n", scan_ok},
      {";D030\r\n", table_type()},
      {";B5\r\n", device_data()},
      {";2B\r\n", target_id()},
      {";D031\r\n", ":D19131D40000\r\n"},
      {";D034\r\n", answer(sl::SoftwareVersionAnswer{"V2.10"}.encode())},
      {";1601010300\r\n", ok1f},
      {";D00D00\r\n", scan_ok},
  };
}

std::string hex2(std::uint8_t v) { return sl::to_hex(std::vector<std::uint8_t>{v}); }

// Every code of the §1.8 tables reaches the caller as a typed Error carrying the device code,
// the class of the wire codec's table, and a hint.
TEST_F(TranscriptTest, EveryScanComAndRemoteErrorIsTyped) {
  const std::vector<std::uint8_t> scan_codes{0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0A};
  const std::vector<std::uint8_t> com_codes{0x01, 0x02, 0x03, 0x04, 0x06, 0x07, 0x08, 0x10};
  const std::vector<std::uint16_t> remote_bits{0x0001, 0x0002, 0x0004, 0x0008, 0x0010, 0x0020, 0x0040, 0x0080,
                                               0x0100, 0x0200, 0x0400, 0x0800, 0x1000, 0x2000, 0x4000, 0x8000};
  auto script = table_connect_script();
  for (auto c : scan_codes) script.push_back({";D002\r\n", ":D180" + hex2(c) + "\r\n"});  // move home
  for (auto c : com_codes) script.push_back({";D024\r\n", ":26" + hex2(c) + "\r\n"});     // status
  for (auto b : remote_bits) {
    std::string rem = hex2(static_cast<std::uint8_t>(b & 0xFF)) + hex2(static_cast<std::uint8_t>(b >> 8));
    script.push_back({";1601010201\r\n", ":1F" + rem + "\r\n"});  // D65, 10°, absolute
  }
  auto p = peer(std::move(script));
  drivers::Spectrolino s(io_.get_executor(), options(p->path()));
  run(io_, s.connect());
  for (auto c : scan_codes) {
    try {
      run(io_, s.home());
      ADD_FAILURE() << "scan error " << hex2(c) << " was not reported";
    } catch (const Error& e) {
      auto d = sl::describe_scan_error(c);
      EXPECT_EQ(e.info().device_code, "spectroscan:" + hex2(c));
      EXPECT_EQ(e.cls(), d.cls) << hex2(c);
      EXPECT_FALSE(e.hint().empty()) << hex2(c);
    }
  }
  for (auto c : com_codes) {
    try {
      run(io_, s.table_status());
      ADD_FAILURE() << "COM error " << hex2(c) << " was not reported";
    } catch (const Error& e) {
      auto d = sl::describe_com_error(c);
      EXPECT_EQ(e.info().device_code, "spectrolino-com:" + hex2(c));
      EXPECT_EQ(e.cls(), d.cls) << hex2(c);
      EXPECT_FALSE(e.hint().empty());
    }
  }
  for (auto b : remote_bits) {
    try {
      run(io_, s.set_colorimetry(sl::Illuminant::D65, sl::Observer::Deg10, sl::WhiteBase::Absolute));
      ADD_FAILURE() << "remote error bit " << b << " was not reported";
    } catch (const Error& e) {
      EXPECT_NE(e.cls(), ErrorClass::internal) << b;
      EXPECT_FALSE(e.info().device_code.empty()) << b;
      EXPECT_FALSE(e.info().transcript.empty());
    }
  }
  EXPECT_TRUE(p->done());
}

TEST_F(TranscriptTest, UnexpectedRequestFailsTheExchange) {
  // A peer that expects a different first request never answers: the driver must end in a typed
  // no_comms after its bounded scan, and the peer records the unexpected bytes.
  auto p = peer({{";00\r\n", ":0B0101030001\r\n"}});
  auto o = options(p->path());
  o.max_baud = 9600;
  drivers::Spectrolino s(io_.get_executor(), o);
  try {
    run(io_, s.connect(), std::chrono::seconds(10));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::no_comms);
  }
  EXPECT_FALSE(p->mismatches().empty());
  peer_.reset();  // the mismatches were the point of this test
  p->stop();
}

}  // namespace
}  // namespace colorlab::test
