#include "colorlab/sim/relay_socket_server.hpp"

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/detached.hpp>
#include <boost/asio/local/stream_protocol.hpp>
#include <boost/asio/read_until.hpp>
#include <boost/asio/redirect_error.hpp>
#include <boost/asio/streambuf.hpp>
#include <boost/asio/use_awaitable.hpp>
#include <boost/asio/write.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/core/error.hpp"

namespace colorlab::sim {

namespace asio = boost::asio;
using local = asio::local::stream_protocol;
using nlohmann::json;

struct RelaySocketServer::Impl {
  std::shared_ptr<RelayBoard> board;
  std::filesystem::path path;
  SwitchHandler on_switch;
  local::acceptor acceptor;
  std::uint64_t requests = 0;
  std::uint8_t last_mask = 0;

  Impl(asio::any_io_executor ex, std::shared_ptr<RelayBoard> b, std::filesystem::path p, SwitchHandler h)
      : board(std::move(b)), path(std::move(p)), on_switch(std::move(h)), acceptor(ex), last_mask(board->mask()) {}

  // Every relay whose contact moved since the last look drives its lamp.
  void follow_board() {
    const std::uint8_t now = board->mask();
    for (int relay = 1; relay <= 8; ++relay) {
      const std::uint8_t bit = static_cast<std::uint8_t>(1u << (relay - 1));
      if ((now ^ last_mask) & bit) on_switch(relay, (now & bit) != 0);
    }
    last_mask = now;
  }
};

namespace {

std::string hex_of(const std::vector<std::uint8_t>& bytes) {
  static constexpr char digits[] = "0123456789ABCDEF";
  std::string s;
  for (auto b : bytes) {
    s.push_back(digits[b >> 4]);
    s.push_back(digits[b & 15]);
  }
  return s;
}

std::vector<std::uint8_t> bytes_of(const std::string& hex) {
  if (hex.size() % 2) throw Error(ErrorClass::bad_data, "report hex has an odd number of digits");
  std::vector<std::uint8_t> out;
  for (std::size_t i = 0; i < hex.size(); i += 2) {
    std::size_t used = 0;
    const int v = std::stoi(hex.substr(i, 2), &used, 16);
    if (used != 2) throw Error(ErrorClass::bad_data, "report hex '" + hex + "' is not hex");
    out.push_back(static_cast<std::uint8_t>(v));
  }
  return out;
}

json operation(RelaySocketServer::Impl& d, drivers::HidTransport& device, const json& req) {
  const std::string op = req.value("op", std::string());
  if (op == "open") {
    device.open();
    d.follow_board();  // a board found again powers up with every relay open
    const auto info = device.info();
    return {
        {"ok", true},
        {"path", info.path},
        {"vendor_id", info.vendor_id},
        {"product_id", info.product_id},
        {"manufacturer", info.manufacturer},
        {"product", info.product},
        {"serial", info.serial},
    };
  }
  if (op == "set_feature") {
    device.send_feature_report(bytes_of(req.at("report").get<std::string>()));
    d.follow_board();
    return {{"ok", true}};
  }
  if (op == "get_feature") {
    const auto data = device.get_feature_report(req.at("report").get<std::uint8_t>(), req.at("length").get<std::size_t>());
    return {{"ok", true}, {"data", hex_of(data)}};
  }
  return {{"ok", false}, {"error", "bad_request"}, {"message", "unknown op '" + op + "' (open, set_feature, get_feature)"}};
}

asio::awaitable<void> serve(std::shared_ptr<RelaySocketServer::Impl> d, local::socket socket) {
  // One connection is one opened device node: its own transport onto the shared board.
  auto device = d->board->make_transport();
  asio::streambuf buf(4096);
  for (;;) {
    boost::system::error_code ec;
    const std::size_t n = co_await asio::async_read_until(socket, buf, '\n', asio::redirect_error(asio::use_awaitable, ec));
    if (ec) break;
    std::string line(asio::buffers_begin(buf.data()), asio::buffers_begin(buf.data()) + static_cast<long>(n));
    buf.consume(n);
    ++d->requests;
    json answer;
    try {
      answer = operation(*d, *device, json::parse(line));
    } catch (const Error& e) {
      // An unplugged board fails every transfer, as hidraw answers ENODEV.
      answer = {{"ok", false}, {"error", e.cls() == ErrorClass::no_comms ? "no_device" : "bad_request"}, {"message", e.info().message}};
    } catch (const std::exception& e) {
      answer = {{"ok", false}, {"error", "bad_request"}, {"message", e.what()}};
    }
    std::string out = answer.dump() + "\n";
    co_await asio::async_write(socket, asio::buffer(out), asio::redirect_error(asio::use_awaitable, ec));
    if (ec) break;
  }
  device->close();
}

asio::awaitable<void> accept_loop(std::shared_ptr<RelaySocketServer::Impl> d) {
  for (;;) {
    boost::system::error_code ec;
    auto socket = co_await d->acceptor.async_accept(asio::redirect_error(asio::use_awaitable, ec));
    if (ec) co_return;
    asio::co_spawn(d->acceptor.get_executor(), serve(d, std::move(socket)), asio::detached);
  }
}

}  // namespace

RelaySocketServer::RelaySocketServer(asio::any_io_executor executor, std::shared_ptr<RelayBoard> board,
                                     std::filesystem::path socket_path, SwitchHandler on_switch)
    : impl_(std::make_shared<Impl>(std::move(executor), std::move(board), std::move(socket_path), std::move(on_switch))) {}

RelaySocketServer::~RelaySocketServer() { stop(); }

void RelaySocketServer::start() {
  std::error_code fec;
  std::filesystem::remove(impl_->path, fec);
  boost::system::error_code ec;
  local::endpoint ep(impl_->path.string());
  impl_->acceptor.open(ep.protocol(), ec);
  if (!ec) impl_->acceptor.bind(ep, ec);
  if (!ec) impl_->acceptor.listen(4, ec);
  if (ec) throw Error(ErrorClass::io_error, "relay board socket " + impl_->path.string() + ": " + ec.message());
  asio::co_spawn(impl_->acceptor.get_executor(), accept_loop(impl_), asio::detached);
}

void RelaySocketServer::stop() {
  boost::system::error_code ec;
  if (!impl_->acceptor.is_open()) return;
  impl_->acceptor.close(ec);
  std::error_code fec;
  std::filesystem::remove(impl_->path, fec);
}

const std::filesystem::path& RelaySocketServer::socket_path() const { return impl_->path; }
std::uint64_t RelaySocketServer::requests() const { return impl_->requests; }

}  // namespace colorlab::sim
