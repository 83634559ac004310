#pragma once
// The device side of a recorded transcript, played on a pty to whatever opens its slave: each
// "host" event must arrive byte for byte (however the kernel chunks it), and the "device" events
// that follow it are then written back. Anything else is a mismatch, reported with its position
// and left unanswered, so the driver under test times out instead of being fed the wrong bytes.
#include <memory>
#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>

#include "colorlab/bringup/recording.hpp"
#include "colorlab/sim/pty.hpp"

namespace colorlab::test {

class ReplayPeer : public std::enable_shared_from_this<ReplayPeer> {
 public:
  ReplayPeer(boost::asio::io_context& io, std::vector<bringup::ByteEvent> events);
  void start();
  void stop();

  const std::string& path() const { return pty_.slave_path(); }
  // Host and device events played so far, of how many.
  std::size_t position() const { return pos_; }
  std::size_t size() const { return events_.size(); }
  bool done() const { return pos_ == events_.size(); }
  const std::string& mismatch() const { return mismatch_; }

 private:
  void read();
  void on_bytes();
  void play_device();

  std::vector<bringup::ByteEvent> events_;  // host and device only
  std::size_t pos_ = 0;
  std::string rx_;
  std::string mismatch_;
  sim::Pty pty_;
  boost::asio::posix::stream_descriptor master_;
  char buf_[1024];
};

}  // namespace colorlab::test
