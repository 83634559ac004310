// The dcttech relay driver against the scripted board: exact feature reports per operation,
// read-back verification, refusal of two lamps, a stuck relay, an unplugged and a replugged board.
#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/hid_relay.hpp"
#include "colorlab/wire/hid_relay_protocol.hpp"
#include "colorlab/sim/relay_board.hpp"
#include "run_support.hpp"

namespace colorlab::test {
namespace {

using drivers::HidRelay;
using drivers::HidRelayOptions;
using drivers::LampMap;
using Report = std::vector<std::uint8_t>;

HidRelayOptions options(bool allow_multiple = false) {
  HidRelayOptions o;
  o.id = "lamps";
  o.lamps = LampMap({{"D65", 1}, {"TL84", 2}, {"CWF", 3}, {"A", 4}}, 8, allow_multiple);
  o.reconnect.initial_backoff = std::chrono::milliseconds(1);
  o.reconnect.max_attempts = 3;
  return o;
}

Report on(int n) { return Report{0x00, 0xFF, static_cast<std::uint8_t>(n), 0, 0, 0, 0, 0, 0}; }
Report off(int n) { return Report{0x00, 0xFD, static_cast<std::uint8_t>(n), 0, 0, 0, 0, 0, 0}; }

class HidRelayTest : public ::testing::Test {
 protected:
  boost::asio::io_context io_;
  sim::RelayBoard board_{4, "LAB01"};
};

TEST(HidRelayProtocol, ReportsMatchTheBoardsDocumentedBytes) {
  EXPECT_EQ(wire::hidrelay::switch_one(3, true), on(3));
  EXPECT_EQ(wire::hidrelay::switch_one(8, false), off(8));
  EXPECT_EQ(wire::hidrelay::switch_all(true), (Report{0, 0xFE, 0, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(wire::hidrelay::switch_all(false), (Report{0, 0xFC, 0, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(wire::hidrelay::set_board_id("ABCDE"), (Report{0, 0xFA, 'A', 'B', 'C', 'D', 'E', 0, 0}));
  auto s = wire::hidrelay::parse_state({'Q', 'W', 'E', 'R', 'T', 0, 0, 0x05});
  EXPECT_EQ(s.id, "QWERT");
  EXPECT_EQ(s.mask, 0x05);
  EXPECT_THROW(wire::hidrelay::parse_state({'Q', 'W', 'E', 'R', 'T', 'Y', 0, 0}), Error);
  EXPECT_THROW(wire::hidrelay::parse_state({'Q', 'W'}), Error);
  EXPECT_THROW(wire::hidrelay::switch_one(9, true), Error);
  EXPECT_EQ(wire::hidrelay::relay_count_from_product("USBRelay2"), 2);
  EXPECT_THROW(wire::hidrelay::relay_count_from_product("HIDRelay"), Error);
}

TEST_F(HidRelayTest, ConnectReadsIdAndState) {
  HidRelay r(io_.get_executor(), board_.make_transport(), options());
  run(io_, r.connect());
  EXPECT_EQ(r.state(), drivers::InstrumentState::ready);
  EXPECT_EQ(r.identity().serial, "LAB01");
  EXPECT_EQ(r.relay_count(), 4);
  EXPECT_TRUE(board_.sent_reports().empty()) << "connecting must not switch anything";
}

TEST_F(HidRelayTest, SwitchingIsBreakBeforeMakeWithReadBackAfterEverySwitch) {
  HidRelay r(io_.get_executor(), board_.make_transport(), options());
  run(io_, r.connect());
  run(io_, r.set_lamps({"D65"}));
  EXPECT_EQ(board_.mask(), 0x01);
  int reads_before = board_.reads();
  run(io_, r.set_lamps({"TL84"}));
  EXPECT_EQ(board_.mask(), 0x02);
  // Exactly: D65 on; then D65 off before TL84 on.
  EXPECT_EQ(board_.sent_reports(), (std::vector<Report>{on(1), off(1), on(2)}));
  // One state read before switching plus one read-back per switch.
  EXPECT_EQ(board_.reads() - reads_before, 3);
  EXPECT_EQ(r.lamps_on(), std::vector<std::string>{"TL84"});
  run(io_, r.set_lamps({}));
  EXPECT_EQ(board_.mask(), 0x00);
}

TEST_F(HidRelayTest, TwoLampsAreRefusedUnlessConfigured) {
  HidRelay r(io_.get_executor(), board_.make_transport(), options());
  run(io_, r.connect());
  try {
    run(io_, r.set_lamps({"D65", "TL84"}));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::conflict);
    EXPECT_FALSE(e.hint().empty());
  }
  EXPECT_TRUE(board_.sent_reports().empty());

  sim::RelayBoard board2(4, "LAB02");
  HidRelay mixed(io_.get_executor(), board2.make_transport(), options(true));
  run(io_, mixed.connect());
  run(io_, mixed.set_lamps({"D65", "A"}));
  EXPECT_EQ(board2.mask(), 0x09);
}

TEST_F(HidRelayTest, UnknownLampIsBadParameter) {
  HidRelay r(io_.get_executor(), board_.make_transport(), options());
  run(io_, r.connect());
  try {
    run(io_, r.set_lamps({"D50"}));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::bad_parameter);
    EXPECT_NE(e.hint().find("D65"), std::string::npos);
  }
}

TEST_F(HidRelayTest, StuckRelayIsHardwareFailAfterBoundedRetries) {
  HidRelay r(io_.get_executor(), board_.make_transport(), options());
  run(io_, r.connect());
  sim::RelayBoardFaults f;
  f.stuck_mask = 0x04;  // CWF's relay
  board_.set_faults(f);
  try {
    run(io_, r.set_lamps({"CWF"}));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::hardware_fail);
    EXPECT_EQ(e.info().device_code, "relay:3");
  }
  EXPECT_EQ(board_.sent_reports().size(), 3u) << "three switch attempts, then stop";
  EXPECT_EQ(r.state(), drivers::InstrumentState::fault);
}

TEST_F(HidRelayTest, UnpluggedBoardIsReconnectedWhenItComesBack) {
  HidRelay r(io_.get_executor(), board_.make_transport(), options());
  run(io_, r.connect());
  run(io_, r.set_lamps({"A"}));
  sim::RelayBoardFaults f;
  f.unplugged = true;
  f.replug_after_opens = 2;
  board_.set_faults(f);
  run(io_, r.set_lamps({"D65"}));
  EXPECT_EQ(board_.mask(), 0x01) << "after the replug (all relays off) D65 alone is on";
  EXPECT_EQ(r.reconnector().attempts_used(), 2);
  EXPECT_EQ(r.state(), drivers::InstrumentState::ready);
}

TEST_F(HidRelayTest, BoardThatStaysUnpluggedEndsInNoCommsWithoutHanging) {
  HidRelay r(io_.get_executor(), board_.make_transport(), options());
  run(io_, r.connect());
  sim::RelayBoardFaults f;
  f.unplugged = true;
  board_.set_faults(f);
  try {
    run(io_, r.set_lamps({"D65"}), std::chrono::seconds(5));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::no_comms);
    EXPECT_NE(std::string(e.what()).find("gave up"), std::string::npos) << e.what();
  }
  EXPECT_EQ(r.state(), drivers::InstrumentState::disconnected);
  EXPECT_EQ(r.reconnector().phase(), drivers::ReconnectPhase::gave_up);
}

TEST_F(HidRelayTest, WrongBoardIdIsRefused) {
  auto o = options();
  o.expected_board_id = "OTHER";
  HidRelay r(io_.get_executor(), board_.make_transport(), o);
  try {
    run(io_, r.connect());
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::protocol_error);
  }
}

TEST_F(HidRelayTest, LampOnRelayBeyondTheBoardIsRefused) {
  auto o = options();
  o.lamps = LampMap({{"D65", 1}, {"UV", 6}}, 8, false);
  HidRelay r(io_.get_executor(), board_.make_transport(), o);
  EXPECT_THROW(run(io_, r.connect()), Error);
}

TEST(LampMapTest, ValidatesOutputs) {
  EXPECT_THROW(LampMap({}, 8, false), Error);
  EXPECT_THROW(LampMap({{"D65", 0}}, 8, false), Error);
  EXPECT_THROW(LampMap({{"D65", 9}}, 8, false), Error);
  EXPECT_THROW(LampMap({{"D65", 1}, {"A", 1}}, 8, false), Error);
  auto m = LampMap::from_json(nlohmann::json{{"D65", 1}, {"TL84", 2}}, 512, false);
  EXPECT_EQ(m.output("TL84"), 2);
  EXPECT_THROW(LampMap::from_json(nlohmann::json{{"D65", "one"}}, 512, false), Error);
}

}  // namespace
}  // namespace colorlab::test
