#pragma once
// Serves one Handler over TCP and/or a Unix socket on the caller's io_context. Per-connection
// limits: header 16 KiB, body protocol::kMaxRequestBody (413 beyond), 30 s idle timeout.
// Malformed HTTP gets a 400 problem+json and the connection closes; the server keeps serving.
#include <filesystem>
#include <memory>
#include <string>

#include <boost/asio/io_context.hpp>

#include "colorlab/http/message.hpp"

namespace colorlab::http {

struct ServerOptions {
  std::string tcp_host = "127.0.0.1";   // empty: no TCP listener
  unsigned short tcp_port = 8765;       // 0: pick a free port (see bound_port())
  std::filesystem::path unix_socket;    // empty: no Unix listener
  std::chrono::seconds idle_timeout{30};
  std::string server_name = "colorlabd";
};

class Server {
 public:
  Server(boost::asio::io_context& io, ServerOptions options, Handler handler);
  ~Server();

  // Binds the listeners (throws Error{io_error} naming the address) and starts accepting.
  void start();
  void stop();
  unsigned short bound_port() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace colorlab::http
