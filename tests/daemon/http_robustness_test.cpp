// colorlabd as a real process, fed malformed HTTP, malformed JSON, unknown routes, oversized
// bodies and headers: every one gets a 4xx application/problem+json and the daemon keeps serving.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <thread>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "colorlab/client/api_client.hpp"
#include "colorlab/testing/daemon.hpp"
#include "colorlab/testing/process.hpp"
#include "colorlab/testing/temp_dir.hpp"

using colorlab::testing::Process;
using colorlab::testing::TempDir;
using nlohmann::json;

namespace {

struct RawReply {
  int status = 0;
  std::string headers;
  std::string body;
};

RawReply exchange_raw(int fd, const std::string& bytes);

RawReply send_raw(unsigned short port, const std::string& bytes) {
  int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  ::inet_pton(AF_INET, "127.0.0.1", &addr.sin_addr);
  EXPECT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  return exchange_raw(fd, bytes);
}

// Requests that change state go over the Unix socket: loopback TCP without a key only reads
// (docs/API.md, "Access"), and these tests are about what the routes make of bad input.
RawReply send_raw_unix(const std::string& path, const std::string& bytes) {
  int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::snprintf(addr.sun_path, sizeof addr.sun_path, "%s", path.c_str());
  EXPECT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  return exchange_raw(fd, bytes);
}

RawReply exchange_raw(int fd, const std::string& bytes) {
  timeval tv{10, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL);
  std::string in;
  char buf[4096];
  ssize_t n;
  while ((n = ::recv(fd, buf, sizeof buf, 0)) > 0) in.append(buf, static_cast<size_t>(n));
  ::close(fd);
  RawReply r;
  auto sp = in.find(' ');
  if (sp != std::string::npos) r.status = std::atoi(in.c_str() + sp + 1);
  auto end = in.find("\r\n\r\n");
  if (end != std::string::npos) {
    r.headers = in.substr(0, end);
    r.body = in.substr(end + 4);
  }
  return r;
}

class DaemonHttp : public ::testing::Test {
 protected:
  void SetUp() override {
    std::ofstream(dir / "colorlabd.toml") << "state_dir = \"state\"\n";
    // The web console's files from a directory of the test's own (console_files.hpp), so what the
    // daemon serves at / does not depend on the build having copied client/web.
    std::filesystem::create_directories(dir / "console");
    std::ofstream(dir / "console" / "index.html") << "<!doctype html><title>console</title>\n";
    ::setenv("COLORLAB_CONSOLE_DIR", (dir / "console").c_str(), 1);
    daemon = std::make_unique<Process>(
        std::vector<std::string>{colorlab::testing::bin_path("colorlabd"), "--config", (dir / "colorlabd.toml").string(),
                                 "--listen", "127.0.0.1:0"},
        dir / "colorlabd.log");
    json endpoint = colorlab::testing::wait_for_endpoint(dir / "state", daemon->pid());
    port = endpoint["port"];
    socket_path = endpoint["unix_socket"];
  }

  void expect_problem(const RawReply& r, int status, const std::string& code) {
    EXPECT_EQ(r.status, status) << r.headers << "\n"
                                << r.body;
    EXPECT_NE(r.headers.find("application/problem+json"), std::string::npos) << r.headers;
    auto j = json::parse(r.body, nullptr, false);
    ASSERT_FALSE(j.is_discarded()) << r.body;
    EXPECT_EQ(j["status"], status);
    EXPECT_EQ(j["code"], code) << r.body;
    EXPECT_TRUE(j.contains("type") && j.contains("title") && j.contains("detail") && j.contains("category"));
  }

  void expect_still_serving() {
    auto r = send_raw(port, "GET /v1 HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
    ASSERT_EQ(r.status, 200) << r.body;
    EXPECT_EQ(json::parse(r.body)["api_version"], "1");
  }

  TempDir dir;
  std::unique_ptr<Process> daemon;
  unsigned short port = 0;
  std::string socket_path;
};

}  // namespace

TEST_F(DaemonHttp, GarbageInsteadOfHttpIsA400) {
  expect_problem(send_raw(port, "HELLO THERE\r\n\r\n"), 400, "bad-http");
  expect_problem(send_raw(port, "GET /v1 HTTP/1.1\r\nHost x\r\n\r\n"), 400, "bad-http");
  expect_still_serving();
}

// A path that is not UTF-8 is quoted back in the problem; JSON must not refuse to write it (a 500).
TEST_F(DaemonHttp, APathThatIsNotUtf8IsStillA404Problem) {
  expect_problem(send_raw(port, "GET /v1/runs/%FF%FE HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"), 404,
                 "not_found");
  expect_problem(send_raw(port, "GET /v1/nowhere/%C3%28 HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"), 404,
                 "not_found");
  expect_still_serving();
}

TEST_F(DaemonHttp, MalformedJsonIsA400) {
  std::string body = "{\"campaign\": \"luminance-spot\", ";
  expect_problem(send_raw_unix(socket_path, "POST /v1/executions HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
                                            "Connection: close\r\nContent-Length: " +
                                                std::to_string(body.size()) + "\r\n\r\n" + body),
                 400, "bad-json");
  expect_still_serving();
}

TEST_F(DaemonHttp, WrongShapesAndMediaTypesAreRefused) {
  auto post = [&](const std::string& ct, const std::string& body) {
    return send_raw_unix(socket_path, "POST /v1/executions HTTP/1.1\r\nHost: x\r\nContent-Type: " + ct +
                                          "\r\nConnection: close\r\nContent-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body);
  };
  expect_problem(post("text/plain", "{}"), 415, "unsupported-media-type");
  expect_problem(post("application/json", "[1,2]"), 400, "bad-request");
  expect_problem(post("application/json", R"({"campaign": "no-such-campaign"})"), 404, "not_found");
  expect_problem(post("application/json", R"({"campaign": "luminance-spot", "params": {"readings": -1}})"), 400,
                 "bad_parameter");
  expect_problem(post("application/json", R"({"campaign": "luminance-spot", "params": {"colour": 1}})"), 400,
                 "bad_parameter");
  expect_still_serving();
}

TEST_F(DaemonHttp, UnknownRoutesAndMethodsAre404And405) {
  expect_problem(send_raw(port, "GET /v2/runs HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"), 404, "not_found");
  expect_problem(send_raw(port, "GET /v1/runs/no-such-run HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"), 404,
                 "not_found");
  expect_problem(send_raw(port, "GET /v1/runs?limit=100000 HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"), 400,
                 "bad_parameter");
  auto r = send_raw_unix(socket_path, "DELETE /v1/runs HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
  expect_problem(r, 405, "method-not-allowed");
  EXPECT_NE(r.headers.find("Allow: GET"), std::string::npos) << r.headers;
  expect_still_serving();
}

// docs/API.md's route list, written out: a method a path does not take is 405, and `Allow` lists
// the path's methods (HEAD wherever GET is). Over the Unix socket, so no scope stands in the way.
TEST_F(DaemonHttp, EveryWrongMethodIs405WithTheRoutesMethodsInAllow) {
  const std::vector<std::tuple<std::string, std::string, std::string>> cases{
      {"DELETE", "/v1/runs", "GET, HEAD"},
      {"POST", "/v1/runs/r1/export", "GET, HEAD"},
      {"DELETE", "/v1/executions", "GET, HEAD, POST"},
      {"PUT", "/v1/queue", "GET, HEAD, POST"},
      {"PATCH", "/v1/queue/q1", "GET, HEAD, DELETE"},
      {"GET", "/v1/queue/start", "POST"},
      {"GET", "/v1/blobs/retention", "POST"},
      {"POST", "/v1/blobs/check", "GET, HEAD"},
      {"GET", "/v1/blobs/abc/locate-chart", "POST"},
      {"PUT", "/v1/keys", "GET, HEAD, POST"},
      {"POST", "/v1/keys/k1", "GET, HEAD, DELETE"},
      {"GET", "/v1/control/acquire", "POST"},
      {"DELETE", "/v1/requests/x", "GET, HEAD, POST"},
      {"POST", "/v1/events/stream", "GET, HEAD"},
  };
  for (const auto& [method, path, allow] : cases) {
    auto r = send_raw_unix(socket_path, method + " " + path + " HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
    expect_problem(r, 405, "method-not-allowed");
    EXPECT_NE(r.headers.find("\r\nAllow: " + allow + "\r\n"), std::string::npos) << method << " " << path << "\n"
                                                                                 << r.headers;
  }
  expect_still_serving();
}

// The order chosen (docs/API.md, "How a request is routed"): the console's files before the access
// check — they are public and a browser loads them before it has a key — and every /v1 request after it.
TEST_F(DaemonHttp, ConsoleFilesAreServedBeforeTheAccessCheckAndTheApiAfterIt) {
  auto page = send_raw(port, "GET / HTTP/1.1\r\nHost: x\r\nAuthorization: Bearer clk_not-a-key\r\nConnection: close\r\n\r\n");
  EXPECT_EQ(page.status, 200) << page.headers << "\n"
                              << page.body;
  EXPECT_NE(page.body.find("<title>console</title>"), std::string::npos) << page.body;
  // Loopback without a key only reads; a write to a console file is the console's 405, not a 401.
  auto write = send_raw(port, "POST /index.html HTTP/1.1\r\nHost: x\r\nContent-Length: 0\r\nConnection: close\r\n\r\n");
  expect_problem(write, 405, "method-not-allowed");
  EXPECT_NE(write.headers.find("\r\nAllow: GET, HEAD\r\n"), std::string::npos) << write.headers;
  // The same wrong key on the API is refused.
  expect_problem(send_raw(port, "GET /v1 HTTP/1.1\r\nHost: x\r\nAuthorization: Bearer clk_not-a-key\r\nConnection: close\r\n\r\n"),
                 401, "key-unknown");
  expect_problem(send_raw(port, "POST /v1/queue/start HTTP/1.1\r\nHost: x\r\nContent-Length: 0\r\nConnection: close\r\n\r\n"),
                 401, "key-required");
  expect_still_serving();
}

TEST_F(DaemonHttp, OversizedBodyAndHeadersAreRefusedBeforeReading) {
  expect_problem(send_raw(port, "POST /v1/executions HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
                                "Content-Length: 50000000\r\n\r\n{"),
                 413, "body-too-large");
  expect_problem(send_raw(port, "GET /v1 HTTP/1.1\r\nHost: x\r\nX-Big: " + std::string(40000, 'a') + "\r\n\r\n"), 431,
                 "header-too-large");
  expect_still_serving();
}

TEST_F(DaemonHttp, KeepAliveServesSeveralRequestsOnOneConnection) {
  auto r = send_raw(port,
                    "GET /v1 HTTP/1.1\r\nHost: x\r\n\r\n"
                    "GET /v1/nope HTTP/1.1\r\nHost: x\r\n\r\n"
                    "GET /v1/instruments HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
  EXPECT_EQ(r.status, 200);
  std::string all = r.headers + r.body;
  EXPECT_NE(all.find("HTTP/1.1 404"), std::string::npos);
  EXPECT_NE(all.find("\"items\":[]"), std::string::npos) << all;
}

TEST_F(DaemonHttp, CampaignWithoutItsInstrumentIsRefusedBeforeAnythingIsStored) {
  colorlab::client::Endpoint ep;
  ep.unix_socket = socket_path;  // the Unix socket serves the same API
  colorlab::client::ApiClient api(ep);
  auto runs_before = api.get("/v1/runs")["items"].size();
  try {
    api.post("/v1/executions", {{"campaign", "luminance-spot"}});
    FAIL() << "a campaign whose instrument is missing was started";
  } catch (const colorlab::client::ApiError& e) {
    EXPECT_EQ(e.problem().status, 404);
    EXPECT_EQ(e.problem().code, "not_found");
    EXPECT_NE(e.problem().detail.find("luminance meter"), std::string::npos) << e.problem().detail;
    EXPECT_FALSE(e.problem().hint.empty());
  }
  EXPECT_EQ(api.get("/v1/runs")["items"].size(), runs_before);
  expect_still_serving();
}
