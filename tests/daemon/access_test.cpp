// Access control without a daemon process: API keys stored only as hashes (the secret is nowhere in
// the database files; the hash agrees with sha256sum), the policy's answer for every transport,
// key and route class (expected from the documented rule, written out here, not from the code),
// revoked keys, last_used_at written at most once per interval, the control lock between two
// clients (lease, renewal, force) on a fake clock, the listener check and the [access] settings.
#include <fstream>
#include <iterator>
#include <regex>

#include <boost/asio/io_context.hpp>
#include <gtest/gtest.h>

#include "colorlab/core/error.hpp"
#include "colorlab/api/access.hpp"
#include "colorlab/daemon/config.hpp"
#include "colorlab/api/control_lock.hpp"
#include "colorlab/store/api_keys.hpp"
#include "colorlab/store/store.hpp"
#include "colorlab/testing/process.hpp"
#include "colorlab/testing/temp_dir.hpp"

using colorlab::Error;
using colorlab::ErrorClass;
using colorlab::daemon::Access;
using colorlab::daemon::AccessOptions;
using colorlab::daemon::Caller;
using colorlab::daemon::ControlLock;
using colorlab::daemon::Scope;
using colorlab::http::HttpRequest;
using colorlab::http::Peer;
using colorlab::store::ApiKeyStore;
using colorlab::store::Store;
using colorlab::testing::TempDir;
using nlohmann::json;
using Transport = Peer::Transport;

namespace {

std::string file_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

HttpRequest request(Transport t, const std::string& method, const std::string& target,
                    const std::optional<std::string>& key = std::nullopt) {
  HttpRequest r;
  r.peer.transport = t;
  r.method = method;
  r.target = target;
  EXPECT_TRUE(r.parse_target());
  if (key) r.headers["authorization"] = "Bearer " + *key;
  return r;
}

struct Route {
  std::string method, target;
  Scope needs;  // from docs/API.md's table, written out independently of required_scope()
};

const std::vector<Route>& routes() {
  static const std::vector<Route> r{
      {"GET", "/v1", Scope::read},
      {"GET", "/v1/runs?limit=5", Scope::read},
      {"HEAD", "/v1/blobs/abc", Scope::read},
      {"GET", "/v1/events/stream", Scope::read},
      {"GET", "/v1/control", Scope::read},
      {"POST", "/v1/executions", Scope::control},
      {"POST", "/v1/executions/x/abort", Scope::control},
      {"POST", "/v1/queue", Scope::control},
      {"DELETE", "/v1/queue/x", Scope::control},
      {"POST", "/v1/queue/start", Scope::control},
      {"POST", "/v1/requests/x", Scope::control},
      {"POST", "/v1/control/acquire", Scope::control},
      {"PUT", "/v1/anything", Scope::control},
      {"GET", "/v1/keys", Scope::admin},
      {"POST", "/v1/keys", Scope::admin},
      {"DELETE", "/v1/keys/x", Scope::admin},
  };
  return r;
}

class AccessTest : public ::testing::Test {
 protected:
  AccessTest() : store(dir / "colorlab.db") {}

  std::string new_key(const std::string& name, const std::string& scope) {
    return ApiKeyStore(store).create(name, scope).secret;
  }

  TempDir dir;
  Store store;
  boost::asio::io_context io;
};

}  // namespace

TEST(ApiKeyFormat, IsClkAnd32RandomBytesInBase64url) {
  std::regex format("clk_[A-Za-z0-9_-]{43}");  // 32 bytes = 43 unpadded base64url characters
  auto a = colorlab::store::generate_api_key();
  auto b = colorlab::store::generate_api_key();
  EXPECT_TRUE(std::regex_match(a, format)) << a;
  EXPECT_TRUE(std::regex_match(b, format)) << b;
  EXPECT_NE(a, b);
}

TEST_F(AccessTest, KeysAreStoredOnlyAsTheirSha256) {
  auto created = ApiKeyStore(store).create("alice-laptop", "control");
  auto secret = created.secret;
  // The hash as an independent tool computes it.
  auto sum = colorlab::testing::run_command({"/bin/sh", "-c", "printf %s '" + secret + "' | sha256sum"});
  ASSERT_EQ(sum.exit_code, 0) << sum.err;
  std::string expected_hash = sum.out.substr(0, 64);
  EXPECT_EQ(colorlab::store::api_key_sha256(secret), expected_hash);
  auto entries = ApiKeyStore(store).entries();
  ASSERT_EQ(entries.count(expected_hash), 1u);
  EXPECT_EQ(entries[expected_hash].name, "alice-laptop");
  // Neither the whole key nor its random part is in any of the database's files.
  std::string random_part = secret.substr(4);
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    auto bytes = file_bytes(entry.path());
    EXPECT_EQ(bytes.find(random_part), std::string::npos) << "the key is readable in " << entry.path();
  }
  // Nor in what the API lists or the event log holds.
  for (const auto& k : ApiKeyStore(store).list()) EXPECT_EQ(k.to_json().dump().find(random_part), std::string::npos);
  for (const auto& e : store.events(0, 100, std::string("access"))) {
    EXPECT_EQ(e.payload.dump().find(random_part), std::string::npos);
    EXPECT_EQ(e.payload.dump().find(expected_hash), std::string::npos);
  }
}

TEST_F(AccessTest, BadNamesAndScopesAreRefused) {
  ApiKeyStore keys(store);
  EXPECT_THROW(keys.create("bob", "superuser"), Error);
  EXPECT_THROW(keys.create("", "read"), Error);
  EXPECT_THROW(keys.create(std::string(101, 'a'), "read"), Error);
  EXPECT_THROW(keys.create("tab\there", "read"), Error);
  try {
    keys.revoke("no-such-key");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::not_found);
  }
}

// Every transport × key × route class against the documented policy.
TEST_F(AccessTest, EachScopeAndRouteClassGetsTheDocumentedAnswer) {
  std::map<std::string, std::optional<std::string>> keys{{"none", std::nullopt},
                                                         {"read", new_key("r", "read")},
                                                         {"control", new_key("c", "control")},
                                                         {"admin", new_key("a", "admin")}};
  Access access(store, io.get_executor());
  for (auto transport : {Transport::unix_socket, Transport::loopback, Transport::remote}) {
    for (const auto& [key_name, key] : keys) {
      // What the request may do: the socket everything; loopback read without a key; the key's scope.
      std::optional<Scope> granted;
      if (transport == Transport::unix_socket) granted = Scope::admin;
      if (transport == Transport::loopback) granted = Scope::read;
      if (key_name != "none") {
        Scope k = key_name == "read" ? Scope::read : key_name == "control" ? Scope::control
                                                                           : Scope::admin;
        if (!granted || *granted < k) granted = k;
      }
      for (const auto& route : routes()) {
        auto r = access.check(request(transport, route.method, route.target, key));
        std::string what = route.method + " " + route.target + " key " + key_name + " transport " +
                           std::to_string(static_cast<int>(transport));
        if ((!granted || *granted < route.needs) && key_name == "none") {
          // No key where one is needed: 401, saying which scope the key must have.
          ASSERT_TRUE(r) << what;
          EXPECT_EQ(r->status, 401) << what;
          EXPECT_EQ(r->content_type, "application/problem+json");
          EXPECT_EQ(r->headers["WWW-Authenticate"].rfind("Bearer", 0), 0u) << what;
          auto body = json::parse(r->body);
          EXPECT_EQ(body["code"], "key-required");
          EXPECT_EQ(body["required_scope"], std::string(to_string(route.needs))) << what;
        } else if (*granted < route.needs) {
          ASSERT_TRUE(r) << what;
          EXPECT_EQ(r->status, 403) << what;
          auto body = json::parse(r->body);
          EXPECT_EQ(body["required_scope"], std::string(to_string(route.needs))) << what;
          EXPECT_NE(body["detail"].get<std::string>().find("needs the '" + std::string(to_string(route.needs)) + "' scope"),
                    std::string::npos)
              << body;
        } else {
          EXPECT_FALSE(r) << what << ": " << (r ? r->body : "");
        }
      }
    }
  }
}

TEST_F(AccessTest, UnknownMalformedAndRevokedKeysAre401OnEveryTransport) {
  auto key = new_key("carol", "control");
  Access access(store, io.get_executor());
  EXPECT_FALSE(access.check(request(Transport::remote, "POST", "/v1/queue/start", key)));
  auto id = ApiKeyStore(store).list().front().id;
  ApiKeyStore(store).revoke(id);
  access.reload();
  for (auto transport : {Transport::unix_socket, Transport::loopback, Transport::remote}) {
    auto r = access.check(request(transport, "GET", "/v1/runs", key));
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 401);
    EXPECT_EQ(json::parse(r->body)["code"], "key-revoked");
    EXPECT_NE(r->headers["WWW-Authenticate"].find("invalid_token"), std::string::npos);

    auto unknown = access.check(request(transport, "GET", "/v1/runs", colorlab::store::generate_api_key()));
    ASSERT_TRUE(unknown);
    EXPECT_EQ(unknown->status, 401);
    EXPECT_EQ(json::parse(unknown->body)["code"], "key-unknown");

    auto req = request(transport, "GET", "/v1/runs");
    req.headers["authorization"] = "Basic dXNlcjpwdw==";
    auto malformed = access.check(req);
    ASSERT_TRUE(malformed);
    EXPECT_EQ(json::parse(malformed->body)["code"], "key-malformed");
  }
  // The scheme is case-insensitive (RFC 6750 uses "Bearer"; clients send "bearer" too).
  auto other = new_key("dave", "read");
  access.reload();
  auto req = request(Transport::remote, "GET", "/v1/runs");
  req.headers["authorization"] = "bearer " + other;
  EXPECT_FALSE(access.check(req));
}

TEST_F(AccessTest, LastUsedIsWrittenAtMostOncePerInterval) {
  auto key = new_key("eve", "read");
  Access access(store, io.get_executor());  // 60 s
  for (int i = 0; i < 5; ++i) EXPECT_FALSE(access.check(request(Transport::remote, "GET", "/v1/runs", key)));
  // One write was posted to the writer's thread for five requests.
  EXPECT_EQ(io.run(), 1u);
  auto listed = ApiKeyStore(store).list();
  ASSERT_EQ(listed.size(), 1u);
  EXPECT_TRUE(listed[0].last_used_at.has_value());

  io.restart();
  AccessOptions every_time;
  every_time.touch_interval = std::chrono::seconds(0);
  Access eager(store, io.get_executor(), every_time);
  for (int i = 0; i < 3; ++i) EXPECT_FALSE(eager.check(request(Transport::remote, "GET", "/v1/runs", key)));
  EXPECT_EQ(io.run(), 3u);
}

TEST_F(AccessTest, LoopbackScopeIsASetting) {
  AccessOptions options;
  options.loopback_scope = Scope::control;
  Access access(store, io.get_executor(), options);
  EXPECT_FALSE(access.check(request(Transport::loopback, "POST", "/v1/queue/start")));
  EXPECT_EQ(access.check(request(Transport::loopback, "GET", "/v1/keys"))->status, 401);
  EXPECT_EQ(access.check(request(Transport::remote, "GET", "/v1/runs"))->status, 401);
}

namespace {

struct FakeClock {
  ControlLock::Clock::time_point now{};
};

Caller key_caller(const std::string& id, const std::string& name, Scope scope) {
  Caller c;
  c.transport = Transport::remote;
  c.scope = scope;
  c.key_id = id;
  c.key_name = name;
  return c;
}

}  // namespace

TEST(ControlLockTest, OneHolderOthersGet409NamingItUntilReleasedOrExpired) {
  FakeClock clock;
  std::vector<json> events;
  ControlLock lock(
      std::chrono::seconds(600), [&](const json& e) { events.push_back(e); }, [&] { return clock.now; });
  auto anna = key_caller("k1", "anna", Scope::control);
  auto ben = key_caller("k2", "ben", Scope::control);

  EXPECT_FALSE(lock.gate(ben));  // nobody holds it: anyone with control may drive
  auto taken = lock.acquire(anna, "anna at the bench", false);
  ASSERT_TRUE(taken.ok);
  EXPECT_EQ(taken.status["holder"], "anna at the bench");

  auto busy = lock.gate(ben);
  ASSERT_TRUE(busy);
  EXPECT_EQ(busy->status, 409);
  auto body = json::parse(busy->body);
  EXPECT_EQ(body["code"], "control-locked");
  EXPECT_EQ(body["holder"], "anna at the bench");
  EXPECT_NE(body["detail"].get<std::string>().find("anna at the bench"), std::string::npos);
  EXPECT_FALSE(lock.acquire(ben, "ben", false).ok);
  EXPECT_FALSE(lock.release(ben, false).ok);
  EXPECT_EQ(lock.acquire(ben, "ben", true).problem.status, 403);  // force is for admins

  // The holder's own requests pass and renew the lease.
  clock.now += std::chrono::seconds(500);
  EXPECT_FALSE(lock.gate(anna));
  clock.now += std::chrono::seconds(500);
  EXPECT_TRUE(lock.gate(ben));
  // Not renewed for a whole lease: released.
  clock.now += std::chrono::seconds(601);
  EXPECT_FALSE(lock.gate(ben));
  EXPECT_FALSE(lock.status()["held"].get<bool>());
  ASSERT_TRUE(lock.acquire(ben, "ben", false).ok);
  ASSERT_TRUE(lock.release(ben, false).ok);

  std::vector<std::string> kinds;
  for (const auto& e : events) kinds.push_back(e["event"]);
  EXPECT_EQ(kinds, (std::vector<std::string>{"acquired", "expired", "acquired", "released"}));
}

TEST(ControlLockTest, TheUnixSocketOrAnAdminBreaksItAndItIsRecorded) {
  FakeClock clock;
  std::vector<json> events;
  ControlLock lock(
      std::chrono::seconds(600), [&](const json& e) { events.push_back(e); }, [&] { return clock.now; });
  auto anna = key_caller("k1", "anna", Scope::control);
  Caller local;
  local.transport = Transport::unix_socket;
  local.scope = Scope::admin;
  ASSERT_TRUE(lock.acquire(anna, "anna", false).ok);
  EXPECT_TRUE(lock.gate(local));  // the socket is subject to the lock too, until it breaks it
  auto broken = lock.release(local, true);
  ASSERT_TRUE(broken.ok);
  EXPECT_FALSE(broken.status["held"].get<bool>());
  ASSERT_TRUE(lock.acquire(anna, "anna", false).ok);
  auto admin = key_caller("k9", "root", Scope::admin);
  auto taken = lock.acquire(admin, "maintenance", true);
  ASSERT_TRUE(taken.ok);
  EXPECT_EQ(taken.status["holder"], "maintenance");
  std::vector<std::string> kinds;
  for (const auto& e : events) kinds.push_back(e["event"]);
  // A forced acquire is a break (of anna's lock) and then a new holder.
  EXPECT_EQ(kinds, (std::vector<std::string>{"acquired", "broken", "acquired", "broken", "acquired"}));
  EXPECT_EQ(events[3]["holder"], "anna");
  EXPECT_EQ(events[3]["by"], "maintenance");
}

TEST_F(AccessTest, AControlRequestWhileAnotherHoldsTheLockIs409AfterTheScopeCheck) {
  auto anna = new_key("anna", "control");
  auto ben = new_key("ben", "control");
  auto reader = new_key("rita", "read");
  ControlLock lock(std::chrono::seconds(600));
  Access access(store, io.get_executor(), {}, &lock);
  ASSERT_TRUE(lock.acquire(access.caller(request(Transport::remote, "POST", "/v1/control/acquire", anna)), "anna", false).ok);
  EXPECT_FALSE(access.check(request(Transport::remote, "POST", "/v1/queue/start", anna)));
  EXPECT_EQ(access.check(request(Transport::remote, "POST", "/v1/queue/start", ben))->status, 409);
  EXPECT_EQ(access.check(request(Transport::remote, "POST", "/v1/queue/start", reader))->status, 403);
  EXPECT_EQ(access.check(request(Transport::loopback, "POST", "/v1/queue/start"))->status, 401);
  EXPECT_EQ(access.check(request(Transport::unix_socket, "POST", "/v1/executions"))->status, 409);
  // Reads are never locked; the lock's own routes decide for themselves (force).
  EXPECT_FALSE(access.check(request(Transport::remote, "GET", "/v1/runs", ben)));
  EXPECT_FALSE(access.check(request(Transport::remote, "POST", "/v1/control/release", ben)));
}

TEST(ListenerCheck, BeyondLoopbackNeedsTlsOrAnExplicitPlaintext) {
  using colorlab::daemon::check_listener;
  using colorlab::daemon::is_loopback_host;
  EXPECT_TRUE(is_loopback_host("127.0.0.1"));
  EXPECT_TRUE(is_loopback_host("127.0.0.2"));
  EXPECT_TRUE(is_loopback_host("::1"));
  EXPECT_TRUE(is_loopback_host("localhost"));
  EXPECT_FALSE(is_loopback_host("0.0.0.0"));
  EXPECT_FALSE(is_loopback_host("::"));
  EXPECT_FALSE(is_loopback_host("192.168.1.20"));
  EXPECT_FALSE(is_loopback_host("lab.example.org"));
  EXPECT_NO_THROW(check_listener("127.0.0.1", false, false));
  EXPECT_NO_THROW(check_listener("", false, false));  // no TCP listener
  EXPECT_THROW(check_listener("0.0.0.0", false, false), Error);
  EXPECT_THROW(check_listener("lab.example.org", false, false), Error);
  EXPECT_NO_THROW(check_listener("0.0.0.0", true, false));
  EXPECT_NO_THROW(check_listener("0.0.0.0", false, true));
}

TEST(AccessConfig, TheSectionIsReadAndCheckedKeyByKey) {
  TempDir dir;
  auto write = [&](const std::string& text) {
    std::ofstream(dir / "c.toml") << text;
    return dir / "c.toml";
  };
  auto c = colorlab::daemon::load_config(write(
      "[access]\nloopback_scope = \"control\"\nallow_plaintext = true\ncontrol_lease_s = 120\n"
      "tls_certificate = \"tls/cert.pem\"\ntls_private_key = \"tls/key.pem\"\n"));
  EXPECT_EQ(c.access.loopback_scope, "control");
  EXPECT_TRUE(c.access.allow_plaintext);
  EXPECT_EQ(c.access.control_lease_s, 120);
  EXPECT_EQ(*c.access.tls_certificate, dir / "tls/cert.pem");
  EXPECT_EQ(*c.access.tls_private_key, dir / "tls/key.pem");

  auto defaults = colorlab::daemon::load_config(write("state_dir = \"s\"\n"));
  EXPECT_EQ(defaults.access.loopback_scope, "read");
  EXPECT_FALSE(defaults.access.allow_plaintext);
  EXPECT_EQ(defaults.access.control_lease_s, 600);

  for (const char* bad : {"[access]\nloopback_scope = \"root\"\n", "[access]\nallow_plaintext = \"yes\"\n",
                          "[access]\ncontrol_lease_s = 0\n", "[access]\ntls_certificate = \"c.pem\"\n",
                          "[access]\nkey = 1\n"}) {
    try {
      colorlab::daemon::load_config(write(bad));
      FAIL() << bad;
    } catch (const Error& e) {
      EXPECT_EQ(e.cls(), ErrorClass::bad_parameter) << bad;
      EXPECT_NE(std::string(e.what()).find("c.toml:"), std::string::npos) << e.what();
    }
  }
}
