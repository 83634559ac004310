// Exact bytes of the DMX USB Pro exchange (instrument-protocols §3a), against a raw pty peer that
// answers label 10 and label 3 with recorded frames and records everything the driver writes.
#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <boost/asio/write.hpp>

#include "colorlab/drivers/enttec_dmx.hpp"
#include "colorlab/sim/pty.hpp"
#include "run_support.hpp"

namespace colorlab::test {
namespace {

using Bytes = std::vector<std::uint8_t>;

class RawWidget : public std::enable_shared_from_this<RawWidget> {
 public:
  explicit RawWidget(boost::asio::io_context& io) : master_(io) { master_.assign(pty_.release_master()); }
  void start() { read(); }
  void stop() {
    boost::system::error_code ignored;
    master_.cancel(ignored);
  }
  const std::string& path() const { return pty_.slave_path(); }
  const Bytes& received() const { return rx_; }

 private:
  void read() {
    master_.async_read_some(boost::asio::buffer(buf_), [self = shared_from_this()](boost::system::error_code ec, std::size_t n) {
      if (ec) return;
      self->rx_.insert(self->rx_.end(), self->buf_, self->buf_ + n);
      self->answer();
      self->read();
    });
  }
  void answer() {
    // Answer each complete request frame once, by label; label 6 gets no reply (output only).
    while (answered_ < rx_.size()) {
      if (rx_.size() - answered_ < 5) return;
      std::size_t len = rx_[answered_ + 2] | (rx_[answered_ + 3] << 8);
      if (rx_.size() - answered_ < len + 5) return;
      std::uint8_t label = rx_[answered_ + 1];
      answered_ += len + 5;
      Bytes reply;
      if (label == 10) reply = {0x7E, 0x0A, 0x04, 0x00, 0x78, 0x56, 0x34, 0x12, 0xE7};  // serial 12345678 (BCD, LE)
      // fw 1.44 (minor 44 = 0x2C, then major 1, as OLA's UsbProWidgetDetector reads them), break 9, MAB 1, 40/s
      if (label == 3) reply = {0x7E, 0x03, 0x05, 0x00, 0x2C, 0x01, 0x09, 0x01, 0x28, 0xE7};
      if (reply.empty()) continue;
      auto r = std::make_shared<Bytes>(std::move(reply));
      boost::asio::async_write(master_, boost::asio::buffer(*r), [r](boost::system::error_code, std::size_t) {});
    }
  }

  sim::Pty pty_;
  boost::asio::posix::stream_descriptor master_;
  std::uint8_t buf_[1024];
  Bytes rx_;
  std::size_t answered_ = 0;
};

TEST(EnttecDmxTranscript, DiscoveryAndOneLampAreTheDocumentedFrames) {
  boost::asio::io_context io;
  auto widget = std::make_shared<RawWidget>(io);
  widget->start();
  drivers::EnttecDmxOptions o;
  o.port = widget->path();
  o.lamps = drivers::LampMap({{"D65", 1}, {"TL84", 2}, {"CWF", 3}, {"A", 4}, {"UV", 5}}, 512, false);
  drivers::EnttecDmx d(io.get_executor(), o);
  run(io, d.connect());
  EXPECT_EQ(d.identity().serial, "12345678");
  EXPECT_EQ(d.identity().firmware, "1.44");
  run(io, d.set_lamps({"TL84"}));
  settle(io, std::chrono::milliseconds(20));

  Bytes expected{0x7E, 0x0A, 0x00, 0x00, 0xE7,               // label 10, no payload
                 0x7E, 0x03, 0x02, 0x00, 0x00, 0x00, 0xE7};  // label 3, user-config size 0
  // Label 6, length 513 (LSB 01, MSB 02): start code 00, then slots 1..512 with slot 2 full.
  Bytes dmx{0x7E, 0x06, 0x01, 0x02, 0x00, 0x00, 0xFF};
  dmx.resize(4 + 513, 0x00);  // header + payload
  dmx.push_back(0xE7);
  expected.insert(expected.end(), dmx.begin(), dmx.end());
  EXPECT_EQ(widget->received(), expected);
  widget->stop();
  settle(io, std::chrono::milliseconds(5));
}

}  // namespace
}  // namespace colorlab::test
