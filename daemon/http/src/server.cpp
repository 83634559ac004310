#include "colorlab/http/server.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <sys/sendfile.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <charconv>
#include <cstdio>
#include <optional>
#include <thread>
#include <type_traits>
#include <vector>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/detached.hpp>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/local/stream_protocol.hpp>
#include <boost/asio/redirect_error.hpp>
#include <boost/asio/ssl.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/asio/this_coro.hpp>
#include <boost/asio/use_awaitable.hpp>
#include <boost/asio/write.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/core/stream_traits.hpp>
#include <boost/beast/http.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/core/log.hpp"
#include "colorlab/protocol/api.hpp"

namespace colorlab::http {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace bhttp = boost::beast::http;
namespace ssl = boost::asio::ssl;
using boost::system::error_code;
using tcp = asio::ip::tcp;
using local = asio::local::stream_protocol;
using TlsStream = ssl::stream<tcp::socket>;

namespace {

// What every session needs; sessions hold it, so a stopped Server never leaves them dangling.
struct Shared {
  AsyncHandler handler;
  ServerOptions options;
  std::shared_ptr<ssl::context> tls;
  std::atomic<unsigned> open{0};
  std::atomic<unsigned long long> accepted{0};
  std::atomic<unsigned long long> refused{0};
};

struct OpenConnection {
  explicit OpenConnection(Shared& s) : shared(s) { ++shared.open; }
  ~OpenConnection() { --shared.open; }
  Shared& shared;
};

template <class Stream>
constexpr bool kIsTls = std::is_same_v<Stream, TlsStream>;

template <class Stream>
void close_stream(Stream& stream) {
  error_code ignored;
  auto& socket = beast::get_lowest_layer(stream);
  socket.shutdown(asio::socket_base::shutdown_both, ignored);
  socket.close(ignored);
}

// Cancels the stream's pending operations unless disarmed in time: the deadline of one write or
// read. The flag keeps a timer that fired just as the operation finished from cancelling the next one.
template <class Stream>
class Deadline {
 public:
  Deadline(Stream& stream, std::chrono::steady_clock::duration after)
      : timer_(stream.get_executor()), armed_(std::make_shared<bool>(true)) {
    timer_.expires_after(after);
    timer_.async_wait([&stream, armed = armed_](error_code ec) {
      if (!ec && *armed) {
        error_code ignored;
        beast::get_lowest_layer(stream).cancel(ignored);
      }
    });
  }
  ~Deadline() {
    *armed_ = false;
    timer_.cancel();
  }
  Deadline(const Deadline&) = delete;
  Deadline& operator=(const Deadline&) = delete;

 private:
  asio::steady_timer timer_;
  std::shared_ptr<bool> armed_;
};

// The Content-Length a handler named itself: a streaming response with one (a blob relayed from a bucket) is
// sent with that length, unframed, its connection kept; a HEAD answers with it and never runs a stream.
std::optional<std::uint64_t> stream_length(const HttpResponse& r) {
  auto it = r.headers.find("Content-Length");
  if (it == r.headers.end()) return std::nullopt;
  std::uint64_t n = 0;
  auto [end, ec] = std::from_chars(it->second.data(), it->second.data() + it->second.size(), n);
  if (ec != std::errc() || end != it->second.data() + it->second.size()) return std::nullopt;
  return n;
}

template <class Message>
void set_common(Message& res, const HttpResponse& r, bool keep_alive, const std::string& server_name) {
  res.set(bhttp::field::server, server_name);
  res.set(bhttp::field::content_type, r.content_type);
  // Every answer, API or console: no MIME sniffing (a JSON body naming a campaign's hostile string is never
  // run as a page), the console never framed by another site (clickjacking its Start and Resume buttons), and
  // no URL of the daemon leaked to another site as a Referer. A handler's own header wins.
  res.set("X-Content-Type-Options", "nosniff");
  res.set("X-Frame-Options", "DENY");
  res.set("Referrer-Policy", "no-referrer");
  for (const auto& [k, v] : r.headers) res.set(k, v);
  res.keep_alive(keep_alive);
}

template <class Stream>
asio::awaitable<void> write_response(Stream& stream, const HttpResponse& r, unsigned version, bool keep_alive,
                                     bool head, const Shared& shared, error_code& ec) {
  Deadline<Stream> deadline(stream, shared.options.idle_timeout);
  if (head) {
    bhttp::response<bhttp::empty_body> res{static_cast<bhttp::status>(r.status), version};
    set_common(res, r, keep_alive, shared.options.server_name);
    res.content_length(stream_length(r).value_or(r.body.size()));
    bhttp::response_serializer<bhttp::empty_body> sr{res};
    co_await bhttp::async_write_header(stream, sr, asio::redirect_error(asio::use_awaitable, ec));
    co_return;
  }
  bhttp::response<bhttp::string_body> res{static_cast<bhttp::status>(r.status), version};
  set_common(res, r, keep_alive, shared.options.server_name);
  res.body() = r.body;
  res.prepare_payload();
  co_await bhttp::async_write(stream, res, asio::redirect_error(asio::use_awaitable, ec));
}

struct FileDescriptor {
  int fd = -1;
  ~FileDescriptor() {
    if (fd >= 0) ::close(fd);
  }
};

// A plain socket sends the file with sendfile(2) (no copy through user space, as nginx does); TLS
// must encrypt, so it reads and writes in large chunks.
template <class Stream>
asio::awaitable<void> send_file_body(Stream& stream, int fd, std::uint64_t offset, std::uint64_t length,
                                     const Shared& shared, error_code& ec) {
  if constexpr (!kIsTls<Stream>) {
    auto& socket = beast::get_lowest_layer(stream);
    socket.native_non_blocking(true, ec);
    if (ec) co_return;
    off_t position = static_cast<off_t>(offset);
    std::uint64_t remaining = length;
    while (remaining > 0) {
      ssize_t n = ::sendfile(socket.native_handle(), fd, &position,
                             static_cast<std::size_t>(std::min<std::uint64_t>(remaining, 1u << 30)));
      if (n > 0) {
        remaining -= static_cast<std::uint64_t>(n);
      } else if (n == 0) {
        ec = asio::error::eof;  // the file is shorter than it was when the response was made
        co_return;
      } else if (errno == EAGAIN || errno == EWOULDBLOCK) {
        Deadline<Stream> deadline(stream, shared.options.idle_timeout);
        co_await socket.async_wait(asio::socket_base::wait_write, asio::redirect_error(asio::use_awaitable, ec));
        if (ec) co_return;
      } else if (errno != EINTR) {
        ec = error_code(errno, boost::system::system_category());
        co_return;
      }
    }
  } else {
    std::vector<char> buffer(256 * 1024);
    std::uint64_t done = 0;
    while (done < length) {
      std::size_t want = static_cast<std::size_t>(std::min<std::uint64_t>(buffer.size(), length - done));
      ssize_t n = ::pread(fd, buffer.data(), want, static_cast<off_t>(offset + done));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        ec = n == 0 ? asio::error::eof : error_code(errno, boost::system::system_category());
        co_return;
      }
      Deadline<Stream> deadline(stream, shared.options.idle_timeout);
      co_await asio::async_write(stream, asio::buffer(buffer.data(), static_cast<std::size_t>(n)),
                                 asio::redirect_error(asio::use_awaitable, ec));
      if (ec) co_return;
      done += static_cast<std::uint64_t>(n);
    }
  }
}

template <class Stream>
asio::awaitable<void> write_file_response(Stream& stream, const HttpResponse& r, unsigned version, bool keep_alive,
                                          bool head, const Shared& shared, error_code& ec) {
  FileDescriptor file{::open(r.file->path.c_str(), O_RDONLY | O_CLOEXEC)};
  if (file.fd < 0) {
    // Checked by the handler a moment ago; gone now (retention, or someone's rm).
    auto gone = HttpResponse::problem(404, "not_found", "Not found", "the file behind this response is gone");
    co_await write_response(stream, gone, version, keep_alive, head, shared, ec);
    co_return;
  }
  bhttp::response<bhttp::empty_body> res{static_cast<bhttp::status>(r.status), version};
  set_common(res, r, keep_alive, shared.options.server_name);
  res.content_length(r.file->length);
  bhttp::response_serializer<bhttp::empty_body> sr{res};
  {
    Deadline<Stream> deadline(stream, shared.options.idle_timeout);
    co_await bhttp::async_write_header(stream, sr, asio::redirect_error(asio::use_awaitable, ec));
  }
  if (ec || head) co_return;
  co_await send_file_body(stream, file.fd, r.file->offset, r.file->length, shared, ec);
}

template <class Stream>
class ChunkWriter final : public StreamWriter {
 public:
  // `length`: a body of known length is written as it comes, unframed; never more than announced.
  ChunkWriter(Stream& stream, std::chrono::milliseconds timeout, std::optional<std::uint64_t> length = std::nullopt)
      : stream_(stream), timeout_(timeout), length_(length) {}

  asio::awaitable<bool> send(std::string_view chunk) override {
    if (!ok_) co_return false;
    if (chunk.empty()) co_return true;
    Deadline<Stream> deadline(stream_, timeout_);
    error_code ec;
    if (length_) {
      if (chunk.size() > *length_ - sent_) {
        ok_ = false;
        co_return false;
      }
      co_await asio::async_write(stream_, asio::buffer(chunk.data(), chunk.size()),
                                 asio::redirect_error(asio::use_awaitable, ec));
    } else {
      co_await asio::async_write(stream_, bhttp::make_chunk(asio::buffer(chunk.data(), chunk.size())),
                                 asio::redirect_error(asio::use_awaitable, ec));
    }
    if (ec) ok_ = false;
    sent_ += chunk.size();
    co_return ok_;
  }
  bool ok() const { return ok_; }
  bool complete() const { return ok_ && length_ && sent_ == *length_; }

 private:
  Stream& stream_;
  std::chrono::milliseconds timeout_;
  std::optional<std::uint64_t> length_;
  std::uint64_t sent_ = 0;
  bool ok_ = true;
};

template <class Stream>
asio::awaitable<void> write_stream_response(Stream& stream, const HttpResponse& r, unsigned version, bool keep_alive,
                                            const Shared& shared, error_code& ec) {
  const std::optional<std::uint64_t> length = stream_length(r);
  bhttp::response<bhttp::empty_body> res{static_cast<bhttp::status>(r.status), version};
  set_common(res, r, length && keep_alive, shared.options.server_name);
  if (length) {
    res.content_length(*length);
  } else {
    res.chunked(true);
  }
  bhttp::response_serializer<bhttp::empty_body> sr{res};
  {
    Deadline<Stream> deadline(stream, shared.options.idle_timeout);
    co_await bhttp::async_write_header(stream, sr, asio::redirect_error(asio::use_awaitable, ec));
  }
  if (ec) co_return;
  ChunkWriter<Stream> writer(stream, shared.options.stream_write_timeout, length);
  try {
    co_await r.stream(writer);
  } catch (const std::exception& e) {
    log::warning("http", std::string("a streaming response ended early: ") + e.what());
  }
  if (length) {
    // Short of its Content-Length, the body can only end by closing: the client sees it truncated.
    if (!writer.complete()) ec = asio::error::eof;
    co_return;
  }
  if (writer.ok()) {
    Deadline<Stream> deadline(stream, shared.options.idle_timeout);
    co_await asio::async_write(stream, bhttp::make_chunk_last(), asio::redirect_error(asio::use_awaitable, ec));
  }
  ec = asio::error::eof;  // a stream ends its connection
}

asio::awaitable<HttpResponse> safe_handle(const Shared& shared, HttpRequest& req) {
  if (!req.parse_target()) {
    co_return HttpResponse::problem(400, "bad-target", "Malformed request target", "cannot parse '" + req.target + "'");
  }
  try {
    co_return co_await shared.handler(req);
  } catch (const Error& e) {
    log::error("http", std::string("handler failed: ") + e.what());
    co_return HttpResponse::problem(500, "internal", "Internal error", e.what(), e.hint());
  } catch (const std::exception& e) {
    log::error("http", std::string("handler failed: ") + e.what());
    co_return HttpResponse::problem(500, "internal", "Internal error", e.what());
  }
}

using Clock = std::chrono::steady_clock;

std::string ms_text(std::chrono::microseconds us) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", static_cast<double>(us.count()) / 1000.0);
  return buf;
}

// The W3C Server Timing header (https://www.w3.org/TR/server-timing/): name;dur=milliseconds, comma-separated. The
// handler may have named its own parts (colorlabd: queue, handler, cpu, store, later); the server adds `app`, its
// own measure from the request read to the answer ready to write, which contains them.
void add_server_timing(HttpResponse& r, std::chrono::microseconds app) {
  const std::string part = server_timing_metric("app", app);
  auto [it, fresh] = r.headers.try_emplace("Server-Timing", part);
  if (!fresh) it->second += ", " + part;
}

void log_slow_answer(const HttpRequest& req, const HttpResponse& r, std::chrono::microseconds total,
                     std::chrono::microseconds app) {
  // The path, never the target: a query could carry anything a client put there.
  auto it = r.headers.find("Server-Timing");
  log::warning("http", "slow answer: " + req.method + " " + req.path + " took " + ms_text(total) + " ms: " +
                           (it == r.headers.end() ? server_timing_metric("app", app) : it->second) + "; writing " +
                           ms_text(total - app) + " ms");
}

HttpResponse read_failure(const error_code& ec) {
  if (ec == bhttp::error::body_limit) {
    return HttpResponse::problem(413, "body-too-large", "Request body too large",
                                 "bodies are limited to " + std::to_string(protocol::kMaxRequestBody) + " bytes");
  }
  if (ec == bhttp::error::header_limit) {
    return HttpResponse::problem(431, "header-too-large", "Request header fields too large",
                                 "headers are limited to 16 KiB");
  }
  return HttpResponse::problem(400, "bad-http", "Malformed HTTP request", ec.message());
}

template <class Stream>
asio::awaitable<void> session(Stream stream, Peer peer, std::shared_ptr<Shared> shared) {
  OpenConnection counted(*shared);
  beast::flat_buffer buffer;
  for (;;) {
    bhttp::request_parser<bhttp::string_body> parser;
    parser.header_limit(16 * 1024);
    parser.body_limit(protocol::kMaxRequestBody);

    error_code ec;
    {
      Deadline<Stream> idle(stream, shared->options.idle_timeout);
      co_await bhttp::async_read(stream, buffer, parser, asio::redirect_error(asio::use_awaitable, ec));
    }
    if (ec == bhttp::error::end_of_stream || ec == asio::error::eof || ec == asio::error::operation_aborted ||
        ec == asio::error::connection_reset || ec == ssl::error::stream_truncated) {
      break;
    }
    if (ec) {
      error_code wec;
      co_await write_response(stream, read_failure(ec), 11, false, false, *shared, wec);
      break;
    }

    auto& msg = parser.get();
    HttpRequest req;
    req.peer = peer;
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
    bool head = req.method == "HEAD";

    const auto received = Clock::now();
    HttpResponse r = co_await safe_handle(*shared, req);
    const auto app = std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - received);
    if (shared->options.server_timing) add_server_timing(r, app);
    if constexpr (std::is_same_v<Stream, TlsStream>) {
      // A browser that once reached the console over HTTPS never falls back to plain HTTP for a year (RFC 6797).
      r.headers.try_emplace("Strict-Transport-Security", "max-age=31536000");
    }
    if (r.stream && !head) {
      co_await write_stream_response(stream, r, version, keep_alive, *shared, ec);
    } else if (r.file) {
      co_await write_file_response(stream, r, version, keep_alive, head, *shared, ec);
    } else {
      co_await write_response(stream, r, version, keep_alive, head, *shared, ec);
    }
    if (shared->options.slow_answer_log.count() > 0 && !r.stream) {
      const auto total = std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - received);
      if (total > shared->options.slow_answer_log) log_slow_answer(req, r, total, app);
    }
    if (ec || !keep_alive) break;
  }
  close_stream(stream);
}

Peer peer_of(const tcp::socket& socket, bool tls) {
  Peer p;
  p.tls = tls;
  error_code ec;
  auto ep = socket.remote_endpoint(ec);
  if (ec) {
    p.transport = Peer::Transport::remote;  // unknown: the strictest
    return p;
  }
  auto address = ep.address();
  if (address.is_v6() && address.to_v6().is_v4_mapped()) {
    address = asio::ip::make_address_v4(asio::ip::v4_mapped, address.to_v6());
  }
  p.transport = address.is_loopback() ? Peer::Transport::loopback : Peer::Transport::remote;
  p.address = address.to_string() + ":" + std::to_string(ep.port());
  return p;
}

template <class Socket>
asio::awaitable<void> refuse(Socket socket, std::shared_ptr<Shared> shared) {
  auto r = HttpResponse::problem(503, "too-many-connections", "Too many connections",
                                 "colorlabd serves at most " + std::to_string(shared->options.max_connections) +
                                     " connections at once",
                                 "close idle connections or retry shortly");
  r.headers["Retry-After"] = "1";
  error_code ec;
  co_await write_response(socket, r, 11, false, false, *shared, ec);
  close_stream(socket);
}

asio::awaitable<void> tls_session(tcp::socket socket, std::shared_ptr<Shared> shared) {
  Peer peer = peer_of(socket, true);
  TlsStream stream(std::move(socket), *shared->tls);
  error_code ec;
  {
    Deadline<TlsStream> deadline(stream, shared->options.idle_timeout);
    co_await stream.async_handshake(ssl::stream_base::server, asio::redirect_error(asio::use_awaitable, ec));
  }
  if (ec) {
    log::info("http", "TLS handshake with " + peer.address + " failed: " + ec.message());
    close_stream(stream);
    co_return;
  }
  co_await session(std::move(stream), std::move(peer), std::move(shared));
}

template <class Acceptor>
asio::awaitable<void> accept_loop(Acceptor& acceptor, asio::io_context& pool, std::shared_ptr<Shared> shared) {
  for (;;) {
    error_code ec;
    // Each connection on its own strand: its timers and its I/O never run at once on two threads.
    typename Acceptor::protocol_type::socket socket(asio::make_strand(pool));
    co_await acceptor.async_accept(socket, asio::redirect_error(asio::use_awaitable, ec));
    if (ec == asio::error::operation_aborted) co_return;
    if (ec) {
      // EMFILE and friends: keep serving the connections we have, try again shortly.
      log::warning("http", "accept failed: " + ec.message());
      asio::steady_timer t(acceptor.get_executor(), std::chrono::milliseconds(100));
      co_await t.async_wait(asio::use_awaitable);
      continue;
    }
    auto executor = socket.get_executor();
    if (shared->open.load() >= shared->options.max_connections) {
      ++shared->refused;
      asio::co_spawn(executor, refuse(std::move(socket), shared), asio::detached);
      continue;
    }
    ++shared->accepted;
    if constexpr (std::is_same_v<Acceptor, local::acceptor>) {
      Peer peer;
      peer.transport = Peer::Transport::unix_socket;
      peer.address = shared->options.unix_socket.string();
      asio::co_spawn(executor, session(std::move(socket), std::move(peer), shared), asio::detached);
    } else if (shared->tls) {
      asio::co_spawn(executor, tls_session(std::move(socket), shared), asio::detached);
    } else {
      Peer peer = peer_of(socket, false);
      asio::co_spawn(executor, session(std::move(socket), std::move(peer), shared), asio::detached);
    }
  }
}

// The TLS policy testssl.sh checks (tests/security/testssl_test.py; docs/configuration.md, "TLS"): TLS 1.2 and
// 1.3 only; for 1.2 only forward-secret AEAD suites (ECDHE with AES-GCM or ChaCha20-Poly1305), in the server's
// order, so no client can talk the daemon down to CBC or static RSA; no TLS compression (CRIME) and no
// renegotiation (a client-driven CPU drain, and CVE-2009-3555's family); no session tickets, whose key would
// live as long as the process and so undo forward secrecy.
void harden(SSL_CTX* ctx) {
  SSL_CTX_set_min_proto_version(ctx, TLS1_2_VERSION);
  SSL_CTX_set_options(ctx, SSL_OP_CIPHER_SERVER_PREFERENCE | SSL_OP_NO_COMPRESSION | SSL_OP_NO_RENEGOTIATION |
                               SSL_OP_NO_TICKET);
  if (SSL_CTX_set_cipher_list(ctx, "ECDHE-ECDSA-AES256-GCM-SHA384:ECDHE-RSA-AES256-GCM-SHA384:"
                                   "ECDHE-ECDSA-CHACHA20-POLY1305:ECDHE-RSA-CHACHA20-POLY1305:"
                                   "ECDHE-ECDSA-AES128-GCM-SHA256:ECDHE-RSA-AES128-GCM-SHA256") != 1 ||
      SSL_CTX_set1_groups_list(ctx, "X25519:P-256:P-384") != 1) {
    throw Error(ErrorClass::internal, "the TLS library refused colorlabd's cipher policy",
                "colorlabd needs OpenSSL 1.1.1 or later with ECDHE and AES-GCM");
  }
}

std::shared_ptr<ssl::context> make_tls_context(const ServerOptions& o) {
  if (o.tls_certificate.empty() && o.tls_private_key.empty()) return nullptr;
  if (o.tls_certificate.empty() || o.tls_private_key.empty()) {
    throw Error(ErrorClass::bad_parameter, "TLS needs both a certificate and a private key",
                "set both tls_certificate and tls_private_key in [api]");
  }
  auto ctx = std::make_shared<ssl::context>(ssl::context::tls_server);
  ctx->set_options(ssl::context::default_workarounds | ssl::context::no_sslv2 | ssl::context::no_sslv3 |
                   ssl::context::no_tlsv1 | ssl::context::no_tlsv1_1 | ssl::context::single_dh_use);
  harden(ctx->native_handle());
  error_code ec;
  ctx->use_certificate_chain_file(o.tls_certificate.string(), ec);
  if (ec) {
    throw Error(ErrorClass::bad_parameter,
                "cannot use TLS certificate " + o.tls_certificate.string() + ": " + ec.message(),
                "a PEM certificate (chain) file readable by colorlabd");
  }
  ctx->use_private_key_file(o.tls_private_key.string(), ssl::context::pem, ec);
  if (ec) {
    throw Error(ErrorClass::bad_parameter,
                "cannot use TLS private key " + o.tls_private_key.string() + ": " + ec.message(),
                "a PEM private key file matching the certificate, readable by colorlabd");
  }
  return ctx;
}

}  // namespace

std::string server_timing_metric(const std::string& name, std::chrono::microseconds duration) {
  return name + ";dur=" + ms_text(duration);
}

struct Server::Impl {
  explicit Impl(asio::io_context& context) : io(context) {}
  asio::io_context& io;
  std::shared_ptr<Shared> shared;
  std::unique_ptr<tcp::acceptor> tcp_acceptor;
  std::unique_ptr<local::acceptor> unix_acceptor;
  std::vector<std::thread> threads;
  // Declared last: destroyed first, while what its pending sessions refer to is still alive.
  std::unique_ptr<asio::io_context> pool;
  std::optional<asio::executor_work_guard<asio::io_context::executor_type>> pool_work;

  asio::io_context& serving_context() { return pool ? *pool : io; }
};

Server::Server(asio::io_context& io, ServerOptions options, Handler handler)
    : Server(io, std::move(options),
             AsyncHandler([handler = std::move(handler)](HttpRequest& req) -> asio::awaitable<HttpResponse> {
               co_return handler(req);
             })) {}

Server::Server(asio::io_context& io, ServerOptions options, AsyncHandler handler)
    : impl_(std::make_shared<Impl>(io)) {
  impl_->shared = std::make_shared<Shared>();
  impl_->shared->handler = std::move(handler);
  impl_->shared->options = std::move(options);
  if (impl_->shared->options.threads > 0) {
    impl_->pool = std::make_unique<asio::io_context>(static_cast<int>(impl_->shared->options.threads));
  }
}

Server::~Server() { stop(); }

void Server::start() {
  auto& o = impl_->shared->options;
  impl_->shared->tls = make_tls_context(o);
  auto& ctx = impl_->serving_context();
  if (!o.tcp_host.empty()) {
    error_code ec;
    auto address = asio::ip::make_address(o.tcp_host, ec);
    if (ec) throw Error(ErrorClass::bad_parameter, "listen address '" + o.tcp_host + "' is not an IP address");
    tcp::endpoint ep(address, o.tcp_port);
    auto acc = std::make_unique<tcp::acceptor>(ctx);
    acc->open(ep.protocol(), ec);
    if (!ec) acc->set_option(asio::socket_base::reuse_address(true), ec);
    if (!ec) acc->bind(ep, ec);
    if (!ec) acc->listen(asio::socket_base::max_listen_connections, ec);
    if (ec) {
      throw Error(ErrorClass::io_error,
                  "cannot listen on " + o.tcp_host + ":" + std::to_string(o.tcp_port) + ": " +
                      ec.message(),
                  "another colorlabd may be running; pick another port with --listen");
    }
    impl_->tcp_acceptor = std::move(acc);
    asio::co_spawn(ctx, accept_loop(*impl_->tcp_acceptor, ctx, impl_->shared), asio::detached);
  }
  if (!o.unix_socket.empty()) {
    std::error_code fec;
    std::filesystem::remove(o.unix_socket, fec);  // a stale socket from a killed daemon
    auto acc = std::make_unique<local::acceptor>(ctx);
    error_code ec;
    local::endpoint ep(o.unix_socket.string());
    acc->open(ep.protocol(), ec);
    if (!ec) acc->bind(ep, ec);
    if (!ec && ::chmod(o.unix_socket.c_str(), 0660) != 0) ec = error_code(errno, boost::system::system_category());
    if (!ec) acc->listen(asio::socket_base::max_listen_connections, ec);
    if (ec) throw Error(ErrorClass::io_error, "cannot listen on " + o.unix_socket.string() + ": " + ec.message());
    impl_->unix_acceptor = std::move(acc);
    asio::co_spawn(ctx, accept_loop(*impl_->unix_acceptor, ctx, impl_->shared), asio::detached);
  }
  if (impl_->pool && impl_->threads.empty()) {
    impl_->pool_work.emplace(impl_->pool->get_executor());
    for (unsigned i = 0; i < o.threads; ++i) {
      impl_->threads.emplace_back([pool = impl_->pool.get()] {
        // Named, so per-thread figures (the latency probe's, top -H) tell the pool that answers from the heavy work.
        pthread_setname_np(pthread_self(), "http-pool");
        pool->run();
      });
    }
  }
}

void Server::stop() {
  auto& impl = *impl_;
  if (impl.pool && !impl.threads.empty()) {
    // Ends open connections too; with the threads joined, the acceptors are ours to close.
    impl.pool_work.reset();
    impl.pool->stop();
    for (auto& t : impl.threads) t.join();
    impl.threads.clear();
  }
  error_code ignored;
  if (impl.tcp_acceptor) impl.tcp_acceptor->close(ignored);
  if (impl.unix_acceptor) {
    impl.unix_acceptor->close(ignored);
    std::error_code fec;
    std::filesystem::remove(impl.shared->options.unix_socket, fec);
  }
  if (impl.pool) {
    impl.tcp_acceptor.reset();
    impl.unix_acceptor.reset();
  }
}

unsigned short Server::bound_port() const {
  if (!impl_->tcp_acceptor) return 0;
  error_code ec;
  auto ep = impl_->tcp_acceptor->local_endpoint(ec);
  return ec ? 0 : ep.port();
}

ServerStats Server::stats() const {
  return {impl_->shared->open.load(), impl_->shared->accepted.load(), impl_->shared->refused.load()};
}

}  // namespace colorlab::http
