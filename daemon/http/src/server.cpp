#include "colorlab/http/server.hpp"

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/detached.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/local/stream_protocol.hpp>
#include <boost/asio/redirect_error.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/use_awaitable.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/http.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/core/log.hpp"
#include "colorlab/protocol/api.hpp"

namespace colorlab::http {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace bhttp = boost::beast::http;
using boost::system::error_code;
using tcp = asio::ip::tcp;
using local = asio::local::stream_protocol;

namespace {

HttpResponse safe_handle(const Handler& handler, HttpRequest& req) {
  if (!req.parse_target()) {
    return HttpResponse::problem(400, "bad-target", "Malformed request target", "cannot parse '" + req.target + "'");
  }
  try {
    return handler(req);
  } catch (const Error& e) {
    log::error("http", std::string("handler failed: ") + e.what());
    return HttpResponse::problem(500, "internal", "Internal error", e.what(), e.hint());
  } catch (const std::exception& e) {
    log::error("http", std::string("handler failed: ") + e.what());
    return HttpResponse::problem(500, "internal", "Internal error", e.what());
  }
}

template <class Socket>
asio::awaitable<void> write_response(Socket& socket, const HttpResponse& r, unsigned version, bool keep_alive,
                                     const std::string& server_name, error_code& ec) {
  bhttp::response<bhttp::string_body> res{static_cast<bhttp::status>(r.status), version};
  res.set(bhttp::field::server, server_name);
  res.set(bhttp::field::content_type, r.content_type);
  for (const auto& [k, v] : r.headers) res.set(k, v);
  res.keep_alive(keep_alive);
  res.body() = r.body;
  res.prepare_payload();
  co_await bhttp::async_write(socket, res, asio::redirect_error(asio::use_awaitable, ec));
}

template <class Socket>
asio::awaitable<void> session(Socket socket, Handler handler, ServerOptions options) {
  beast::flat_buffer buffer;
  asio::steady_timer idle(socket.get_executor());
  for (;;) {
    bhttp::request_parser<bhttp::string_body> parser;
    parser.header_limit(16 * 1024);
    parser.body_limit(protocol::kMaxRequestBody);

    idle.expires_after(options.idle_timeout);
    idle.async_wait([&socket](error_code ec) {
      if (!ec) {
        error_code ignored;
        socket.cancel(ignored);
      }
    });
    error_code ec;
    co_await bhttp::async_read(socket, buffer, parser, asio::redirect_error(asio::use_awaitable, ec));
    idle.cancel();

    if (ec == bhttp::error::end_of_stream || ec == asio::error::eof || ec == asio::error::operation_aborted ||
        ec == asio::error::connection_reset) {
      break;
    }
    if (ec) {
      HttpResponse r = ec == bhttp::error::body_limit
                           ? HttpResponse::problem(413, "body-too-large", "Request body too large",
                                                   "bodies are limited to " +
                                                       std::to_string(protocol::kMaxRequestBody) + " bytes")
                       : ec == bhttp::error::header_limit
                           ? HttpResponse::problem(431, "header-too-large", "Request header fields too large",
                                                   "headers are limited to 16 KiB")
                           : HttpResponse::problem(400, "bad-http", "Malformed HTTP request", ec.message());
      error_code wec;
      co_await write_response(socket, r, 11, false, options.server_name, wec);
      break;
    }

    auto& msg = parser.get();
    HttpRequest req;
    req.method = std::string(msg.method_string());
    req.target = std::string(msg.target());
    for (const auto& field : msg) {
      std::string name(field.name_string());
      for (auto& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      req.headers[name] = std::string(field.value());
    }
    req.body = std::move(msg.body());
    bool keep_alive = msg.keep_alive();
    unsigned version = msg.version();

    HttpResponse r = safe_handle(handler, req);
    co_await write_response(socket, r, version, keep_alive, options.server_name, ec);
    if (ec || !keep_alive) break;
  }
  error_code ignored;
  socket.shutdown(asio::socket_base::shutdown_both, ignored);
  socket.close(ignored);
}

template <class Acceptor>
asio::awaitable<void> accept_loop(Acceptor& acceptor, const Handler& handler, ServerOptions options) {
  for (;;) {
    error_code ec;
    auto socket = co_await acceptor.async_accept(asio::redirect_error(asio::use_awaitable, ec));
    if (ec == asio::error::operation_aborted) co_return;
    if (ec) {
      // EMFILE and friends: keep serving the connections we have, try again shortly.
      log::warning("http", "accept failed: " + ec.message());
      asio::steady_timer t(acceptor.get_executor(), std::chrono::milliseconds(100));
      co_await t.async_wait(asio::use_awaitable);
      continue;
    }
    asio::co_spawn(acceptor.get_executor(), session(std::move(socket), handler, options), asio::detached);
  }
}

}  // namespace

struct Server::Impl {
  asio::io_context& io;
  ServerOptions options;
  Handler handler;
  std::unique_ptr<tcp::acceptor> tcp_acceptor;
  std::unique_ptr<local::acceptor> unix_acceptor;
};

Server::Server(asio::io_context& io, ServerOptions options, Handler handler)
    : impl_(std::make_unique<Impl>(Impl{io, std::move(options), std::move(handler), nullptr, nullptr})) {}

Server::~Server() { stop(); }

void Server::start() {
  auto& o = impl_->options;
  if (!o.tcp_host.empty()) {
    error_code ec;
    auto address = asio::ip::make_address(o.tcp_host, ec);
    if (ec) throw Error(ErrorClass::bad_parameter, "listen address '" + o.tcp_host + "' is not an IP address");
    tcp::endpoint ep(address, o.tcp_port);
    auto acc = std::make_unique<tcp::acceptor>(impl_->io);
    acc->open(ep.protocol(), ec);
    if (!ec) acc->set_option(asio::socket_base::reuse_address(true), ec);
    if (!ec) acc->bind(ep, ec);
    if (!ec) acc->listen(asio::socket_base::max_listen_connections, ec);
    if (ec) {
      throw Error(ErrorClass::io_error, "cannot listen on " + o.tcp_host + ":" + std::to_string(o.tcp_port) + ": " +
                                            ec.message(),
                  "another colorlabd may be running; pick another port with --listen");
    }
    impl_->tcp_acceptor = std::move(acc);
    asio::co_spawn(impl_->io, accept_loop(*impl_->tcp_acceptor, impl_->handler, o), asio::detached);
  }
  if (!o.unix_socket.empty()) {
    std::error_code fec;
    std::filesystem::remove(o.unix_socket, fec);  // a stale socket from a killed daemon
    auto acc = std::make_unique<local::acceptor>(impl_->io);
    error_code ec;
    local::endpoint ep(o.unix_socket.string());
    acc->open(ep.protocol(), ec);
    if (!ec) acc->bind(ep, ec);
    if (!ec) acc->listen(asio::socket_base::max_listen_connections, ec);
    if (ec) throw Error(ErrorClass::io_error, "cannot listen on " + o.unix_socket.string() + ": " + ec.message());
    impl_->unix_acceptor = std::move(acc);
    asio::co_spawn(impl_->io, accept_loop(*impl_->unix_acceptor, impl_->handler, o), asio::detached);
  }
}

void Server::stop() {
  error_code ignored;
  if (impl_->tcp_acceptor) impl_->tcp_acceptor->close(ignored);
  if (impl_->unix_acceptor) {
    impl_->unix_acceptor->close(ignored);
    std::error_code fec;
    std::filesystem::remove(impl_->options.unix_socket, fec);
  }
}

unsigned short Server::bound_port() const {
  if (!impl_->tcp_acceptor) return 0;
  error_code ec;
  auto ep = impl_->tcp_acceptor->local_endpoint(ec);
  return ec ? 0 : ep.port();
}

}  // namespace colorlab::http
