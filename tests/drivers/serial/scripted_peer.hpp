#pragma once
// A tiny scripted instrument on a pty for recorded-transcript tests: it expects exactly the listed
// request lines, in order, and answers each with the recorded reply. A line sent at a speed the
// step does not allow is ignored (a real device sees framing garbage); any other unexpected line is
// recorded as a mismatch and left unanswered, so the driver's exchange must match byte for byte.
#include <memory>
#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <boost/asio/write.hpp>

#include "colorlab/drivers/transcript.hpp"
#include "colorlab/sim/pty.hpp"

namespace colorlab::test {

struct ScriptStep {
  std::string expect;    // full request line including CR LF
  std::string reply;     // full answer line including CR LF
  unsigned baud = 0;     // the client must have set this speed (0 = any)
  bool rts_cts = false;  // the client must have enabled RTS/CTS
};

class ScriptedPeer : public std::enable_shared_from_this<ScriptedPeer> {
 public:
  ScriptedPeer(boost::asio::io_context& io, std::vector<ScriptStep> steps)
      : steps_(std::move(steps)), master_(io) {
    master_.assign(pty_.release_master());
  }
  void start() { read(); }
  void stop() {
    boost::system::error_code ignored;
    master_.cancel(ignored);
  }
  const std::string& path() const { return pty_.slave_path(); }
  bool done() const { return pos_ == steps_.size(); }
  std::size_t position() const { return pos_; }
  const std::vector<std::string>& mismatches() const { return mismatches_; }
  std::size_t ignored() const { return ignored_; }

 private:
  void read() {
    master_.async_read_some(boost::asio::buffer(buf_), [self = shared_from_this()](boost::system::error_code ec, std::size_t n) {
      if (ec) return;
      self->line_.append(self->buf_, n);
      std::size_t nl;
      while ((nl = self->line_.find('\n')) != std::string::npos) {
        std::string line = self->line_.substr(0, nl + 1);
        self->line_.erase(0, nl + 1);
        self->on_line(line);
      }
      self->read();
    });
  }
  void on_line(const std::string& line) {
    if (done()) {
      mismatches_.push_back("after the script ended: " + drivers::Transcript::escape(line));
      return;
    }
    const ScriptStep& s = steps_[pos_];
    auto settings = pty_.client_settings();
    if (s.baud != 0 && settings.baud != s.baud) {
      ++ignored_;
      return;
    }
    if (line != s.expect) {
      mismatches_.push_back("step " + std::to_string(pos_) + ": expected " + drivers::Transcript::escape(s.expect) + ", got " +
                            drivers::Transcript::escape(line));
      return;
    }
    if (s.rts_cts && !settings.rts_cts) {
      mismatches_.push_back("step " + std::to_string(pos_) + ": RTS/CTS not enabled");
      return;
    }
    ++pos_;
    auto reply = std::make_shared<std::string>(s.reply);
    boost::asio::async_write(master_, boost::asio::buffer(*reply), [reply](boost::system::error_code, std::size_t) {});
  }

  std::vector<ScriptStep> steps_;
  std::size_t pos_ = 0;
  std::vector<std::string> mismatches_;
  std::size_t ignored_ = 0;
  sim::Pty pty_;
  boost::asio::posix::stream_descriptor master_;
  char buf_[512];
  std::string line_;
};

}  // namespace colorlab::test
