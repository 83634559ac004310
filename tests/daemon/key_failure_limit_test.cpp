// Wrong API keys limited per address (issue 27: "after 10 failures a minute from one address, 429 for a
// minute"), on a fake clock: the count, its one-minute window, the block's length and Retry-After, the block
// applying to the address whatever it sends (a right key too), other addresses and the Unix socket untouched,
// the table bounded under a flood of addresses, and the refusal itself (problem+json, no key in it).
#include <gtest/gtest.h>

#include "colorlab/api/access.hpp"
#include "colorlab/api/key_failure_limit.hpp"
#include "colorlab/store/api_keys.hpp"
#include "colorlab/store/store.hpp"
#include "colorlab/testing/temp_dir.hpp"

#include <boost/asio/io_context.hpp>

using colorlab::daemon::Access;
using colorlab::daemon::AccessOptions;
using colorlab::daemon::KeyFailureLimit;
using colorlab::http::HttpRequest;
using colorlab::http::Peer;
using nlohmann::json;
using namespace std::chrono_literals;
using Clock = KeyFailureLimit::Clock;

namespace {

// The numbers, written out: 10 failures within a minute, then a minute refused.
constexpr int kFailures = 10;

TEST(KeyFailureLimit, TheTenthFailureWithinAMinuteBlocksTheAddressForAMinute) {
  KeyFailureLimit limit;
  const auto t0 = Clock::time_point{} + 1000s;
  for (int i = 1; i < kFailures; ++i) {
    EXPECT_FALSE(limit.failed("10.0.0.5", t0 + i * 5s)) << "failure " << i;
    EXPECT_FALSE(limit.blocked("10.0.0.5", t0 + i * 5s)) << "blocked after " << i << " failures";
  }
  EXPECT_TRUE(limit.failed("10.0.0.5", t0 + 50s)) << "the tenth failure within 60 s starts the block";
  EXPECT_EQ(limit.blocked("10.0.0.5", t0 + 50s), 60s);
  EXPECT_EQ(limit.blocked("10.0.0.5", t0 + 80s), 30s);
  EXPECT_EQ(limit.blocked("10.0.0.5", t0 + 109s + 500ms), 1s) << "rounded up: never Retry-After: 0";
  // More failures while refused neither extend the block nor start it again (no second log line).
  EXPECT_FALSE(limit.failed("10.0.0.5", t0 + 100s));
  EXPECT_FALSE(limit.blocked("10.0.0.5", t0 + 110s)) << "a minute after it began, the block is over";
  EXPECT_FALSE(limit.blocked("10.0.0.6", t0 + 60s)) << "another address was never blocked";
  // After the block the count starts again from zero: one more wrong key is not a new block.
  EXPECT_FALSE(limit.failed("10.0.0.5", t0 + 111s));
  EXPECT_FALSE(limit.blocked("10.0.0.5", t0 + 111s));
}

TEST(KeyFailureLimit, FailuresSpreadBeyondAMinuteAreNotBlocked) {
  KeyFailureLimit limit;
  const auto t0 = Clock::time_point{} + 1000s;
  // Nine in the first minute, nine in the next: never ten within one minute of the first of them.
  for (int i = 0; i < kFailures - 1; ++i) EXPECT_FALSE(limit.failed("10.0.0.5", t0 + i * 1s));
  for (int i = 0; i < kFailures - 1; ++i) EXPECT_FALSE(limit.failed("10.0.0.5", t0 + 60s + i * 1s));
  EXPECT_FALSE(limit.blocked("10.0.0.5", t0 + 70s));
}

TEST(KeyFailureLimit, TheTableStaysBoundedUnderAFloodOfAddresses) {
  KeyFailureLimit::Options o;
  o.max_addresses = 64;
  KeyFailureLimit limit(o);
  const auto t0 = Clock::time_point{} + 1000s;
  for (int i = 0; i < 10000; ++i) limit.failed("10.1." + std::to_string(i / 256) + "." + std::to_string(i % 256), t0);
  EXPECT_LE(limit.addresses(), o.max_addresses);
}

class LimitedAccess : public ::testing::Test {
 protected:
  LimitedAccess() : store(dir / "colorlab.db") {
    right = colorlab::store::ApiKeyStore(store).create("lab", "control").secret;
    AccessOptions o;
    o.now = [this] { return now; };
    access = std::make_unique<Access>(store, io.get_executor(), o);
  }
  HttpRequest request(Peer::Transport t, const std::string& address, const std::string& key) {
    HttpRequest r;
    r.peer.transport = t;
    r.peer.address = address;
    r.method = "GET";
    r.target = "/v1/runs";
    EXPECT_TRUE(r.parse_target());
    r.headers["authorization"] = "Bearer " + key;
    return r;
  }
  colorlab::testing::TempDir dir;
  colorlab::store::Store store;
  boost::asio::io_context io;
  std::string right;
  Clock::time_point now = Clock::time_point{} + 5000s;
  std::unique_ptr<Access> access;
};

TEST_F(LimitedAccess, TenWrongKeysThen429ForTheAddressEvenWithTheRightKey) {
  const std::string wrong = "clk_WrongWrongWrongWrongWrongWrongWrongWrong123";
  for (int i = 0; i < kFailures; ++i) {
    now += 1s;
    // Each from a new connection (its own port): the limit is per machine.
    auto r = access->check(request(Peer::Transport::remote, "192.0.2.7:" + std::to_string(40000 + i), wrong));
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 401) << "failure " << i + 1 << " is still answered as a wrong key";
  }
  now += 1s;
  auto refused = access->check(request(Peer::Transport::remote, "192.0.2.7:41000", right));
  ASSERT_TRUE(refused) << "the right key from a blocked address was let in";
  EXPECT_EQ(refused->status, 429);
  EXPECT_EQ(refused->content_type, "application/problem+json");
  EXPECT_EQ(refused->headers["Retry-After"], "59");  // the block began at the tenth failure, a second ago
  auto body = json::parse(refused->body);
  EXPECT_EQ(body["code"], "key-failures");
  EXPECT_EQ(body["retry_after_s"], 59);
  EXPECT_EQ(refused->body.find(right), std::string::npos);
  EXPECT_EQ(refused->body.find(wrong), std::string::npos);

  // Not the neighbours, not the Unix socket.
  EXPECT_FALSE(access->check(request(Peer::Transport::remote, "192.0.2.8:41000", right)));
  EXPECT_FALSE(access->check(request(Peer::Transport::unix_socket, "/run/colorlab/colorlabd.sock", right)));

  now += 59s;
  EXPECT_FALSE(access->check(request(Peer::Transport::remote, "192.0.2.7:41001", right)))
      << "a minute after the block began the right key works again";
}

TEST_F(LimitedAccess, LoopbackIsLimitedToo) {
  // A guesser on the lab PC itself is still a guesser; only the socket file's permissions outrank the limit.
  for (int i = 0; i < kFailures; ++i) {
    access->check(request(Peer::Transport::loopback, "127.0.0.1:5000" + std::to_string(i), "clk_nope"));
  }
  auto r = access->check(request(Peer::Transport::loopback, "127.0.0.1:6000", right));
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 429);
}

}  // namespace
