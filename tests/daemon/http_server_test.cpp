// The HTTP server in-process, on its own thread pool: streamed responses drop a client that stops
// reading (nothing queues up for it), files go out byte-exact, a HEAD gets headers only, TLS
// listeners speak TLS (checked with openssl s_client, an independent client), and the connection
// cap answers 503 instead of growing.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <fstream>
#include <random>
#include <thread>

#include <boost/asio/io_context.hpp>
#include <nlohmann/json.hpp>
#include <gtest/gtest.h>

#include "colorlab/core/error.hpp"
#include "colorlab/http/server.hpp"
#include "colorlab/testing/process.hpp"
#include "colorlab/testing/temp_dir.hpp"

using colorlab::http::HttpRequest;
using colorlab::http::HttpResponse;
using colorlab::http::Server;
using colorlab::http::ServerOptions;
using colorlab::testing::TempDir;

namespace {

int connect_to(unsigned short port, int receive_buffer = 0) {
  int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (receive_buffer > 0) ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof receive_buffer);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  ::inet_pton(AF_INET, "127.0.0.1", &addr.sin_addr);
  EXPECT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  timeval tv{10, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  return fd;
}

std::string exchange(unsigned short port, const std::string& request) {
  int fd = connect_to(port);
  ::send(fd, request.data(), request.size(), MSG_NOSIGNAL);
  std::string in;
  char buf[65536];
  ssize_t n;
  while ((n = ::recv(fd, buf, sizeof buf, 0)) > 0) in.append(buf, static_cast<size_t>(n));
  ::close(fd);
  return in;
}

struct PoolServer {
  explicit PoolServer(ServerOptions o, colorlab::http::Handler handler) {
    o.tcp_host = "127.0.0.1";
    o.tcp_port = 0;
    o.threads = 2;
    server = std::make_unique<Server>(io, std::move(o), std::move(handler));
    server->start();
  }
  boost::asio::io_context io;  // unused by a pool server, but the constructor wants one
  std::unique_ptr<Server> server;
};

}  // namespace

TEST(HttpServer, AStreamWhoseClientStopsReadingIsDroppedAndNothingQueuesForIt) {
  std::atomic<long long> produced{0};
  std::atomic<bool> ended{false};
  ServerOptions o;
  o.stream_write_timeout = std::chrono::milliseconds(300);
  PoolServer s(o, [&](const HttpRequest&) {
    HttpResponse r;
    r.content_type = "text/event-stream";
    r.stream = [&](colorlab::http::StreamWriter& out) -> boost::asio::awaitable<void> {
      std::string chunk(64 * 1024, 'x');
      while (co_await out.send(chunk)) produced += static_cast<long long>(chunk.size());
      ended = true;
    };
    return r;
  });
  int fd = connect_to(s.server->bound_port(), 4096);
  std::string req = "GET /stream HTTP/1.1\r\nHost: x\r\n\r\n";
  ::send(fd, req.data(), req.size(), MSG_NOSIGNAL);
  // Read nothing: the producer must give up once a chunk waits longer than the deadline.
  for (int i = 0; i < 100 && !ended; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_TRUE(ended) << "the stalled client was not dropped";
  // What left the producer is what the kernel's buffers hold, not an ever-growing queue.
  EXPECT_LT(produced.load(), 64LL * 1024 * 1024);
  ::close(fd);
  EXPECT_EQ(s.server->stats().open_connections, 0u);
}

TEST(HttpServer, FileRangesAreByteExactAndHeadSendsHeadersOnly) {
  TempDir dir;
  std::string content(3 * 1024 * 1024 + 17, '\0');
  std::mt19937 rng(5);
  for (auto& c : content) c = static_cast<char>(rng());
  auto path = dir / "blob.bin";
  std::ofstream(path, std::ios::binary).write(content.data(), static_cast<std::streamsize>(content.size()));
  PoolServer s({}, [&](const HttpRequest& req) {
    HttpResponse r;
    r.content_type = "application/octet-stream";
    std::uint64_t offset = req.path == "/part" ? 1000 : 0;
    std::uint64_t length = req.path == "/part" ? 2 * 1024 * 1024 : content.size();
    r.status = req.path == "/part" ? 206 : 200;
    r.file = colorlab::http::FileSpan{path, offset, length};
    return r;
  });
  auto whole = exchange(s.server->bound_port(), "GET /whole HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
  auto body_at = whole.find("\r\n\r\n");
  ASSERT_NE(body_at, std::string::npos);
  EXPECT_EQ(whole.substr(body_at + 4), content);
  auto part = exchange(s.server->bound_port(), "GET /part HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
  EXPECT_EQ(part.rfind("HTTP/1.1 206", 0), 0u);
  EXPECT_EQ(part.substr(part.find("\r\n\r\n") + 4), content.substr(1000, 2 * 1024 * 1024));
  auto head = exchange(s.server->bound_port(), "HEAD /whole HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
  EXPECT_NE(head.find("Content-Length: " + std::to_string(content.size())), std::string::npos) << head;
  EXPECT_EQ(head.substr(head.find("\r\n\r\n") + 4), "");
}

TEST(HttpServer, TheConnectionCapAnswers503) {
  ServerOptions o;
  o.max_connections = 4;
  PoolServer s(o, [](const HttpRequest&) { return HttpResponse::json(200, nlohmann::json::object()); });
  std::vector<int> idle;
  for (int i = 0; i < 4; ++i) idle.push_back(connect_to(s.server->bound_port()));
  for (int i = 0; i < 50 && s.server->stats().open_connections < 4; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  auto refused = exchange(s.server->bound_port(), "GET / HTTP/1.1\r\nHost: x\r\n\r\n");
  EXPECT_EQ(refused.rfind("HTTP/1.1 503", 0), 0u) << refused;
  for (int fd : idle) ::close(fd);
}

TEST(HttpServer, ATlsListenerSpeaksTlsToOpensslsClient) {
  TempDir dir;
  auto key = dir / "key.pem";
  auto cert = dir / "cert.pem";
  auto made = colorlab::testing::run_command({"/usr/bin/openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-subj",
                                              "/CN=127.0.0.1", "-days", "1", "-keyout", key.string(), "-out",
                                              cert.string()});
  ASSERT_EQ(made.exit_code, 0) << made.err;
  ServerOptions o;
  o.tls_certificate = cert;
  o.tls_private_key = key;
  PoolServer s(o, [](const HttpRequest& req) { return HttpResponse::json(200, {{"tls", req.peer.tls}}); });
  std::string port = std::to_string(s.server->bound_port());
  auto out = colorlab::testing::run_command(
      {"/bin/sh", "-c",
       "printf 'GET / HTTP/1.1\\r\\nHost: x\\r\\nConnection: close\\r\\n\\r\\n' | openssl s_client -quiet -CAfile " +
           cert.string() + " -verify_return_error -connect 127.0.0.1:" + port + " 2>/dev/null"});
  EXPECT_NE(out.out.find("{\"tls\":true}"), std::string::npos) << out.out << out.err;
  // Plain HTTP to a TLS listener gets no HTTP answer.
  auto plain = exchange(s.server->bound_port(), "GET / HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
  EXPECT_EQ(plain.find("{\"tls\""), std::string::npos);
  // An unusable certificate is a typed error at start, naming the file.
  ServerOptions bad;
  bad.tls_certificate = dir / "missing.pem";
  bad.tls_private_key = key;
  bad.tcp_port = 0;
  boost::asio::io_context io;
  Server broken(io, bad, [](const HttpRequest&) { return HttpResponse{}; });
  try {
    broken.start();
    FAIL() << "a missing certificate was accepted";
  } catch (const colorlab::Error& e) {
    EXPECT_NE(std::string(e.what()).find("missing.pem"), std::string::npos) << e.what();
  }
}
