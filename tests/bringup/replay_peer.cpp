#include "replay_peer.hpp"

#include <boost/asio/write.hpp>

#include "colorlab/bringup/transcript_file.hpp"

namespace colorlab::test {

using bringup::ByteEvent;

ReplayPeer::ReplayPeer(boost::asio::io_context& io, std::vector<ByteEvent> events) : master_(io) {
  for (auto& e : events) {
    if (e.kind == ByteEvent::Kind::host || e.kind == ByteEvent::Kind::device) events_.push_back(std::move(e));
  }
  master_.assign(pty_.release_master());
}

void ReplayPeer::start() {
  play_device();  // bytes a device sent before colorlab said anything
  read();
}

void ReplayPeer::stop() {
  boost::system::error_code ignored;
  master_.cancel(ignored);
}

void ReplayPeer::read() {
  master_.async_read_some(boost::asio::buffer(buf_), [self = shared_from_this()](boost::system::error_code ec, std::size_t n) {
    if (ec) return;
    self->rx_.append(self->buf_, n);
    self->on_bytes();
    self->read();
  });
}

void ReplayPeer::on_bytes() {
  while (mismatch_.empty() && !rx_.empty()) {
    if (done()) {
      mismatch_ = "the driver sent " + bringup::to_hex(rx_) + " after the transcript's last event";
      return;
    }
    const std::string& want = events_[pos_].data;
    const std::size_t n = std::min(want.size(), rx_.size());
    if (rx_.compare(0, n, want, 0, n) != 0) {
      mismatch_ = "event " + std::to_string(pos_) + ": the transcript has the host send " + bringup::to_hex(want) +
                  ", the driver sent " + bringup::to_hex(rx_.substr(0, want.size())) +
                  " (did the probing order or a driver's request change? then record the transcript again)";
      return;
    }
    if (rx_.size() < want.size()) return;  // the rest of this write is still on its way
    rx_.erase(0, want.size());
    ++pos_;
    play_device();
  }
}

void ReplayPeer::play_device() {
  while (!done() && events_[pos_].kind == ByteEvent::Kind::device) {
    auto bytes = std::make_shared<std::string>(events_[pos_].data);
    boost::asio::async_write(master_, boost::asio::buffer(*bytes), [bytes](boost::system::error_code, std::size_t) {});
    ++pos_;
  }
}

}  // namespace colorlab::test
