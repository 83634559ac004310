#include "colorlab/sim/control_channel.hpp"

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/detached.hpp>
#include <boost/asio/local/stream_protocol.hpp>
#include <boost/asio/read_until.hpp>
#include <boost/asio/redirect_error.hpp>
#include <boost/asio/streambuf.hpp>
#include <boost/asio/use_awaitable.hpp>
#include <boost/asio/write.hpp>

#include "colorlab/core/error.hpp"

namespace colorlab::sim {

namespace asio = boost::asio;
using local = asio::local::stream_protocol;

struct ControlChannel::Impl {
  std::filesystem::path path;
  Handler handler;
  local::acceptor acceptor;
  Impl(asio::io_context& io, std::filesystem::path p, Handler h) : path(std::move(p)), handler(std::move(h)), acceptor(io) {}
};

namespace {

asio::awaitable<void> serve(local::socket socket, std::shared_ptr<ControlChannel::Impl> impl) {
  asio::streambuf buf(64 * 1024);
  for (;;) {
    boost::system::error_code ec;
    std::size_t n = co_await asio::async_read_until(socket, buf, '\n', asio::redirect_error(asio::use_awaitable, ec));
    if (ec) co_return;
    std::string line(asio::buffers_begin(buf.data()), asio::buffers_begin(buf.data()) + static_cast<long>(n));
    buf.consume(n);
    auto cmd = nlohmann::json::parse(line, nullptr, false);
    nlohmann::json answer = cmd.is_discarded()
                                ? nlohmann::json{{"ok", false}, {"error", "bad_data"}, {"message", "not JSON"}}
                                : impl->handler(cmd);
    std::string out = answer.dump() + "\n";
    co_await asio::async_write(socket, asio::buffer(out), asio::redirect_error(asio::use_awaitable, ec));
    if (ec) co_return;
  }
}

asio::awaitable<void> accept_loop(std::shared_ptr<ControlChannel::Impl> impl) {
  for (;;) {
    boost::system::error_code ec;
    auto socket = co_await impl->acceptor.async_accept(asio::redirect_error(asio::use_awaitable, ec));
    if (ec) co_return;
    asio::co_spawn(impl->acceptor.get_executor(), serve(std::move(socket), impl), asio::detached);
  }
}

}  // namespace

ControlChannel::ControlChannel(asio::io_context& io, std::filesystem::path path, Handler handler)
    : impl_(std::make_shared<Impl>(io, std::move(path), std::move(handler))) {
  std::error_code fec;
  std::filesystem::remove(impl_->path, fec);
  boost::system::error_code ec;
  local::endpoint ep(impl_->path.string());
  impl_->acceptor.open(ep.protocol(), ec);
  if (!ec) impl_->acceptor.bind(ep, ec);
  if (!ec) impl_->acceptor.listen(16, ec);
  if (ec) throw Error(ErrorClass::io_error, "control socket " + impl_->path.string() + ": " + ec.message());
  asio::co_spawn(io, accept_loop(impl_), asio::detached);
}

ControlChannel::~ControlChannel() {
  boost::system::error_code ignored;
  impl_->acceptor.close(ignored);
  std::error_code fec;
  std::filesystem::remove(impl_->path, fec);
}

const std::filesystem::path& ControlChannel::path() const { return impl_->path; }

nlohmann::json send_control_command(const std::filesystem::path& path, const nlohmann::json& command) {
  asio::io_context io;
  local::socket s(io);
  boost::system::error_code ec;
  s.connect(local::endpoint(path.string()), ec);
  if (ec) throw Error(ErrorClass::no_comms, "cannot reach the simulator's control socket " + path.string() + ": " + ec.message());
  std::string out = command.dump() + "\n";
  asio::write(s, asio::buffer(out), ec);
  asio::streambuf buf;
  if (!ec) asio::read_until(s, buf, '\n', ec);
  if (ec) throw Error(ErrorClass::no_comms, "simulator control channel: " + ec.message());
  std::string line(asio::buffers_begin(buf.data()), asio::buffers_end(buf.data()));
  return nlohmann::json::parse(line);
}

}  // namespace colorlab::sim
