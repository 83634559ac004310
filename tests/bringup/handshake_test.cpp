// The recognisers read replies by each protocol's documented shape (../shared/docs/
// instrument-protocols.md: §3a the widget's 7E … E7 frame, §2 the LS-110's "OKnn"/"ERxx" lines,
// §1.6 the SpectroScan's ":D183xx" status and a stand-alone Spectrolino's ":26xx" COM error), bytes
// written here by hand, not by colorlab's encoders; and a hand-written transcript replayed to
// doctor's examination through the ReplayPeer.
#include <future>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/use_future.hpp>
#include <gtest/gtest.h>

#include "colorlab/bringup/examine.hpp"
#include "colorlab/bringup/handshake.hpp"
#include "colorlab/core/error.hpp"
#include "replay_peer.hpp"

namespace colorlab::test {
namespace {

namespace bu = colorlab::bringup;
using namespace std::string_literals;

TEST(Recognise, AWidgetFrameIsTheDmxWidget) {
  // Label 10 reply: 7E 0A, length 4 00, serial 78 56 34 12 (BCD, little-endian), E7.
  auto h = bu::recognise("\x7e\x0a\x04\x00\x78\x56\x34\x12\xe7"s);
  EXPECT_EQ(h.kind, "dmx");
  EXPECT_NE(h.detail.find("label 10"), std::string::npos) << h.detail;
}

TEST(Recognise, AFrameWithoutItsEndByteIsNotAWidget) {
  EXPECT_EQ(bu::recognise("\x7e\x0a\x04\x00\x78\x56\x34\x12\x7e"s).kind, "");
}

TEST(Recognise, OkAndErLinesAreTheLs110EvenWithParityBitsSet) {
  EXPECT_EQ(bu::recognise("OK00\r\n").kind, "ls110");
  EXPECT_EQ(bu::recognise("ER00\r\n").kind, "ls110");
  // 7E2 read as 8 bits: 'O' (0x4F, five ones: even parity bit 1) arrives as 0xCF.
  EXPECT_EQ(bu::recognise("\xcfK00\r\n"s).kind, "ls110");
}

TEST(Recognise, SpectroScanStatusAndStandaloneComErrorAreTheSpectrolino) {
  auto table = bu::recognise(":D18310\r\n");
  EXPECT_EQ(table.kind, "spectrolino");
  EXPECT_NE(table.detail.find("SpectroScan"), std::string::npos) << table.detail;
  auto alone = bu::recognise(":2601\r\n");
  EXPECT_EQ(alone.kind, "spectrolino");
  EXPECT_NE(alone.detail.find("stand-alone"), std::string::npos) << alone.detail;
}

TEST(Recognise, NoiseIsNoProtocol) {
  EXPECT_EQ(bu::recognise("\x13\x37garbage\xff\r\n"s).kind, "");
  EXPECT_EQ(bu::recognise("").kind, "");
  EXPECT_EQ(bu::recognise("ATZ\r\nOK\r\n").kind, "");  // a modem's "OK" lacks the two status digits
}

TEST(ProbeOrder, TheExpectedKindComesFirst) {
  EXPECT_EQ(bu::probe_order(""), (std::vector<std::string>{"dmx", "ls110", "spectrolino"}));
  EXPECT_EQ(bu::probe_order("spectrolino"), (std::vector<std::string>{"spectrolino", "dmx", "ls110"}));
  EXPECT_THROW(bu::probe_order("modem"), Error);
}

// The budget for a port that answers nothing: the bound is 5 s.
TEST(HandshakeBudget, ASilentPortCostsTheSumOfTheDeadlines) {
  bu::HandshakeOptions o;
  EXPECT_EQ(bu::handshake_budget(o), std::chrono::milliseconds(400 + 1500 + 500 + 500));
}

bu::Examination examine(boost::asio::io_context& io, std::shared_ptr<ReplayPeer> peer, bu::ExamineOptions o) {
  bu::Recording rec;
  auto fut = boost::asio::co_spawn(io, bu::examine_port(io.get_executor(), peer->path(), o, rec), boost::asio::use_future);
  auto limit = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (fut.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
    io.run_one_for(std::chrono::milliseconds(50));
    if (std::chrono::steady_clock::now() > limit) throw std::runtime_error("examination hung");
  }
  return fut.get();
}

bu::ByteEvent host(std::string b) { return {bu::ByteEvent::Kind::host, 0, std::move(b)}; }
bu::ByteEvent device(std::string b) { return {bu::ByteEvent::Kind::device, 0, std::move(b)}; }

// An LS-110 from the protocol document: silent to the widget's label 10, "OK00" to MDS,04, then the
// reading's MDS,04 and MES ("OK00,  245.50": the last field is the value).
TEST(ReplayPeer, PlaysAHandWrittenLs110ToTheDriver) {
  boost::asio::io_context io;
  auto peer = std::make_shared<ReplayPeer>(
      io, std::vector<bu::ByteEvent>{host("\x7e\x0a\x00\x00\xe7"s), host("MDS,04\r\n"), device("OK00\r\n"), host("MDS,04\r\n"),
                                     device("OK00\r\n"), host("MES\r\n"), device("OK00,  245.50\r\n")});
  peer->start();
  bu::ExamineOptions o;
  o.measure = true;
  auto x = examine(io, peer, o);
  peer->stop();
  EXPECT_EQ(x.verdict, "identified") << x.message;
  EXPECT_EQ(x.kind, "ls110");
  EXPECT_DOUBLE_EQ(x.decoded.value("luminance", 0.0), 245.50);
  EXPECT_TRUE(peer->done()) << peer->position() << " of " << peer->size();
  EXPECT_EQ(peer->mismatch(), "");
}

TEST(ReplayPeer, ADifferentRequestIsAMismatchNotAnAnswer) {
  boost::asio::io_context io;
  auto peer = std::make_shared<ReplayPeer>(io, std::vector<bu::ByteEvent>{host("MES\r\n"), device("OK00,  1.00\r\n")});
  peer->start();
  bu::ExamineOptions o;
  o.expect = "ls110";
  auto x = examine(io, peer, o);
  peer->stop();
  EXPECT_NE(peer->mismatch().find("4d44532c30"), std::string::npos) << peer->mismatch();  // "MDS,0"
  EXPECT_NE(x.verdict, "identified");
}

}  // namespace
}  // namespace colorlab::test
