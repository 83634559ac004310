// Every answer of a real colorlabd carries a Server-Timing header (the W3C's; issue 27) saying where its time went:
// the wait for the thread that runs its handler, the handler's run (of it on a CPU and on the store's writer), a
// heavy route's later answer, and the whole from the request read to the answer ready. Checked on main-thread
// routes, a pool route and a refused one: every part present and well-formed, the nested parts within the parts
// they belong to, and the parts' sum no longer than the answer as the client timed it — which holds on any
// machine, fast or loaded, so no bound here is a timing threshold.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cctype>
#include <chrono>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "colorlab/testing/daemon.hpp"
#include "colorlab/testing/temp_dir.hpp"

using colorlab::testing::DaemonProcess;
using colorlab::testing::TempDir;

namespace {

struct Answer {
  std::string head;      // status line and headers
  double client_ms = 0;  // from connecting to the last byte read
};

// One request on its own connection (Connection: close), timed from before the connect to the answer's end.
Answer ask(unsigned short port, const std::string& method, const std::string& path) {
  Answer a;
  const auto t0 = std::chrono::steady_clock::now();
  int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  ::inet_pton(AF_INET, "127.0.0.1", &addr.sin_addr);
  EXPECT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0) << "cannot connect to colorlabd";
  timeval tv{20, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  const std::string body = method == "POST" ? "{\"answer\":\"go\"}" : "";
  std::string request = method + " " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n";
  if (!body.empty()) request += "Content-Type: application/json\r\nContent-Length: " + std::to_string(body.size()) + "\r\n";
  request += "\r\n" + body;
  ::send(fd, request.data(), request.size(), MSG_NOSIGNAL);
  std::string in;
  char buf[65536];
  ssize_t n;
  while ((n = ::recv(fd, buf, sizeof buf, 0)) > 0) in.append(buf, static_cast<size_t>(n));
  ::close(fd);
  a.client_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  a.head = in.substr(0, in.find("\r\n\r\n"));
  return a;
}

// "queue;dur=0.04, handler;dur=0.61, …" → {queue: 0.04, handler: 0.61, …}; a malformed part fails the test.
std::map<std::string, double> server_timing(const std::string& head) {
  std::map<std::string, double> parts;
  std::istringstream lines(head);
  std::string line;
  while (std::getline(lines, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string name = "server-timing:";
    if (line.size() < name.size()) continue;
    std::string lower = line.substr(0, name.size());
    for (auto& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (lower != name) continue;
    std::istringstream items(line.substr(name.size()));
    std::string item;
    while (std::getline(items, item, ',')) {
      const auto start = item.find_first_not_of(' ');
      item = item.substr(start == std::string::npos ? item.size() : start);
      const auto dur = item.find(";dur=");
      EXPECT_NE(dur, std::string::npos) << "a Server-Timing part without a duration: '" << item << "'";
      if (dur == std::string::npos) continue;
      std::size_t used = 0;
      const double ms = std::stod(item.substr(dur + 5), &used);
      EXPECT_EQ(dur + 5 + used, item.size()) << "a malformed duration in '" << item << "'";
      parts[item.substr(0, dur)] = ms;
    }
  }
  return parts;
}

}  // namespace

TEST(server_timing, EveryAnswerSaysWhereItsTimeWentWithinWhatTheClientMeasured) {
  TempDir dir;
  const auto config = dir / "colorlabd.toml";
  // The embedded simulated lab without its GigE camera (no loopback port held): the routes' handlers are what is
  // timed here, not the lab.
  std::ofstream(dir / "lab.toml") << "[genicam]\nenabled = false\n";
  std::ofstream(config) << "[simulator]\nenabled = true\ntime_scale = 100\nseed = 7\nconfig = \"lab.toml\"\n";
  DaemonProcess daemon(dir / "state", config);
  const auto colon = daemon.url().rfind(':');
  const auto port = static_cast<unsigned short>(std::stoi(daemon.url().substr(colon + 1)));

  struct Case {
    std::string method, path, why;
  };
  const Case cases[] = {{"GET", "/v1", "main thread"},
                        {"GET", "/v1/control", "main thread"},
                        {"GET", "/v1/queue", "main thread"},
                        {"GET", "/v1/runs", "HTTP pool"},
                        {"GET", "/v1/runs/no-such-run", "HTTP pool, refused"},
                        {"POST", "/v1/requests/no-such-request", "main thread, refused"}};
  for (int round = 0; round < 3; ++round) {
    for (const auto& c : cases) {
      SCOPED_TRACE(c.method + " " + c.path + " (" + c.why + ")");
      const Answer a = ask(port, c.method, c.path);
      ASSERT_EQ(a.head.rfind("HTTP/1.1 ", 0), 0u) << "no HTTP answer: '" << a.head << "'";
      const auto parts = server_timing(a.head);
      for (const char* name : {"queue", "handler", "cpu", "store", "later", "app"}) {
        ASSERT_TRUE(parts.count(name)) << "no '" << name << "' in Server-Timing; the answer's head:\n"
                                       << a.head;
        EXPECT_GE(parts.at(name), 0.0) << name;
      }
      // Nested intervals on one clock: the store's wait within the handler's run; the disjoint parts within the
      // server's own measure, and that within the client's (which adds the connect, the read and the write).
      // The values are printed rounded to 0.01 ms: three summed may gain up to 0.015 ms, `app` lose 0.005.
      EXPECT_LE(parts.at("store"), parts.at("handler"));
      EXPECT_LE(parts.at("queue") + parts.at("handler") + parts.at("later"), parts.at("app") + 0.03);
      EXPECT_LE(parts.at("app"), a.client_ms);
      EXPECT_LE(parts.at("cpu"), a.client_ms);
    }
  }
}
