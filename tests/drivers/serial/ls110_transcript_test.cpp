// The LS-110 wire format pinned to byte transcripts written by hand from the protocol document
// (../shared/docs/instrument-protocols.md §2: 4800 7E2, commands and replies end in CR LF, "MDS,04"
// to connect, "MES" answered "OKnn,<space-padded value>" whose last whitespace-separated field is the
// luminance, "ERxx" for errors) — not produced by our encoder. The driver and the simulator share
// colorlab::ls110's codec, so each is held to the document separately: the driver against a scripted
// peer replaying these bytes, the simulator by reading its raw bytes with the document's own rule.
#include <termios.h>
#include <unistd.h>

#include <cmath>
#include <sstream>

#include <gtest/gtest.h>

#include "colorlab/drivers/ls110.hpp"
#include "colorlab/sim/ls110_sim.hpp"
#include "run_support.hpp"
#include "scripted_peer.hpp"

namespace colorlab::test {
namespace {

class Ls110Transcript : public ::testing::Test {
 protected:
  std::shared_ptr<ScriptedPeer> peer(std::vector<ScriptStep> steps) {
    peer_ = std::make_shared<ScriptedPeer>(io_, std::move(steps));
    peer_->start();
    return peer_;
  }
  drivers::Ls110Options options() const {
    drivers::Ls110Options o;
    o.port = peer_->path();
    o.reply_timeout = std::chrono::milliseconds(800);
    o.attempts = 1;
    return o;
  }
  void TearDown() override {
    if (peer_) peer_->stop();
  }
  boost::asio::io_context io_;
  std::shared_ptr<ScriptedPeer> peer_;
};

TEST_F(Ls110Transcript, ConnectThenMeasureByteForByte) {
  auto p = peer({{"MDS,04\r\n", "OK00\r\n"},
                 {"MES\r\n", "OK00,   245.50\r\n"},
                 {"MES\r\n", "OK11,     0.87\r\n"}});
  drivers::Ls110 meter(io_.get_executor(), options());
  run(io_, meter.connect());
  auto a = run(io_, meter.measure_luminance());
  auto b = run(io_, meter.measure_luminance());
  EXPECT_DOUBLE_EQ(a.luminance, 245.50);
  EXPECT_DOUBLE_EQ(b.luminance, 0.87);  // the status digits after OK are not the value
  EXPECT_TRUE(p->done());
  EXPECT_TRUE(p->mismatches().empty()) << p->mismatches().front();
}

TEST_F(Ls110Transcript, ErrorRepliesBecomeTypedErrorsWithTheMetersCode) {
  peer({{"MDS,04\r\n", "OK00\r\n"}, {"MES\r\n", "ER10\r\n"}, {"MES\r\n", "ER30\r\n"}});
  drivers::Ls110 meter(io_.get_executor(), options());
  run(io_, meter.connect());
  for (const char* code : {"ER10", "ER30"}) {
    try {
      run(io_, meter.measure_luminance());
      FAIL() << code << " was taken for a reading";
    } catch (const Error& e) {
      EXPECT_EQ(e.info().device_code, code);
      EXPECT_FALSE(e.hint().empty());
    }
  }
}

TEST_F(Ls110Transcript, RefusedModeIsAnErrorNotAConnection) {
  peer({{"MDS,04\r\n", "ER00\r\n"}});
  drivers::Ls110 meter(io_.get_executor(), options());
  EXPECT_THROW(run(io_, meter.connect()), Error);
  EXPECT_NE(meter.state(), drivers::InstrumentState::ready);
}

// The simulator read with the document's rule, through raw termios at 4800 7E2: it answers "MES" with a
// line "OK" + two digits + "," + a space-padded number, and that number (split()[-1]) is its truth.
TEST(Ls110SimulatorAgainstTheDocument, AnswersMesInTheDocumentedShape) {
  boost::asio::io_context io;
  const double truth = 312.25;
  auto sim = std::make_shared<sim::Ls110Sim>(
      io.get_executor(), [&] { return sim::Ls110Truth{truth, 0.0}; }, 3, 50.0);
  sim->start();
  std::thread served([&] { io.run_for(std::chrono::seconds(5)); });
  int fd = ::open(sim->port_path().c_str(), O_RDWR | O_NOCTTY);
  ASSERT_GE(fd, 0);
  termios t{};
  ::tcgetattr(fd, &t);
  ::cfmakeraw(&t);
  ::cfsetispeed(&t, B4800);
  ::cfsetospeed(&t, B4800);
  t.c_cflag |= PARENB | CSTOPB;
  t.c_cflag &= ~PARODD;
  t.c_cc[VMIN] = 0;
  t.c_cc[VTIME] = 10;
  ::tcsetattr(fd, TCSANOW, &t);
  auto exchange = [&](const std::string& command) {
    EXPECT_EQ(::write(fd, command.data(), command.size()), static_cast<ssize_t>(command.size()));
    std::string line;
    char c;
    for (int i = 0; i < 200 && (line.size() < 2 || line.substr(line.size() - 2) != "\r\n"); ++i) {
      if (::read(fd, &c, 1) == 1) line += static_cast<char>(c & 0x7F);  // 7 data bits
    }
    return line;
  };
  EXPECT_EQ(exchange("MDS,04\r\n").substr(0, 2), "OK");
  std::string reply = exchange("MES\r\n");
  ::close(fd);
  io.stop();
  served.join();
  ASSERT_GE(reply.size(), 7u) << reply;
  EXPECT_EQ(reply.substr(0, 2), "OK");
  EXPECT_TRUE(std::isdigit(static_cast<unsigned char>(reply[2])) && std::isdigit(static_cast<unsigned char>(reply[3]))) << reply;
  EXPECT_EQ(reply[4], ',');
  EXPECT_EQ(reply.substr(reply.size() - 2), "\r\n");
  std::istringstream words(reply.substr(5));
  std::string last, w;
  while (words >> w) last = w;
  EXPECT_NEAR(std::stod(last), truth, 0.005) << reply;
}

}  // namespace
}  // namespace colorlab::test
