#pragma once
// Serves one handler over TCP (plain or TLS) and/or a Unix socket. Per-connection limits: header
// 16 KiB, body protocol::kMaxRequestBody (413 beyond), idle timeout; at most max_connections at
// once (beyond that a connection gets 503 and is closed). Malformed HTTP gets a 400 problem+json
// and the connection closes; the server keeps serving.
//
// Threads: with threads = 0 everything runs on the caller's io_context; with threads = N the
// server runs its own pool of N threads, each connection on its own strand, and the handler is
// called there — it decides itself what must run elsewhere (colorlabd sends every route that
// touches live state to its main thread and serves stored data on the pool).
#include <chrono>
#include <filesystem>
#include <memory>
#include <string>

#include <boost/asio/awaitable.hpp>
#include <boost/asio/io_context.hpp>

#include "colorlab/http/message.hpp"

namespace colorlab::http {

struct ServerOptions {
  std::string tcp_host = "127.0.0.1";  // empty: no TCP listener
  unsigned short tcp_port = 8765;      // 0: pick a free port (see bound_port())
  std::filesystem::path unix_socket;   // empty: no Unix listener (created mode 0660: its permissions are its guard)
  std::chrono::seconds idle_timeout{30};
  std::string server_name = "colorlabd";
  unsigned threads = 0;
  // Both set: the TCP listener speaks TLS (PEM files; TLS 1.2 and newer).
  std::filesystem::path tls_certificate;
  std::filesystem::path tls_private_key;
  // A streaming response (SSE) whose client does not take a chunk within this time is dropped.
  std::chrono::milliseconds stream_write_timeout{10000};
  unsigned max_connections = 1024;
  // Every answer carries a Server-Timing header: the handler's own parts, if it set the header, and `app`, the
  // time from the request read to the answer ready. Cheap, and how a client tells a wait in the daemon from one
  // on the network or on its own machine (issue 27).
  bool server_timing = true;
  // An answer that took longer than this from its request read to its last byte written is logged with where
  // its time went, writing included (0: never).
  std::chrono::microseconds slow_answer_log{0};
};

using AsyncHandler = std::function<boost::asio::awaitable<HttpResponse>(HttpRequest&)>;

// One Server-Timing metric, `name;dur=` in milliseconds with two decimals (https://www.w3.org/TR/server-timing/):
// how a handler writes its own parts, so they read like the server's `app`.
std::string server_timing_metric(const std::string& name, std::chrono::microseconds duration);

struct ServerStats {
  unsigned open_connections = 0;
  unsigned long long accepted = 0;
  unsigned long long refused = 0;  // over max_connections
};

class Server {
 public:
  Server(boost::asio::io_context& io, ServerOptions options, Handler handler);
  Server(boost::asio::io_context& io, ServerOptions options, AsyncHandler handler);
  ~Server();

  // Binds the listeners (throws Error{io_error} naming the address, Error{bad_parameter} for an
  // unusable certificate) and starts accepting.
  void start();
  // Stops accepting; with its own pool, also ends open connections and joins the threads.
  void stop();
  unsigned short bound_port() const;
  ServerStats stats() const;

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

}  // namespace colorlab::http
