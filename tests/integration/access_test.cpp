// Access control through a real colorlabd, its real listeners and the real client and CLI: reads
// open and control refused without a key over loopback TCP, everything open over the Unix socket,
// 200/401/403 per key scope and route class, a revoked key refused, secrets nowhere in the
// database files, two keys contending for the control lock (409 naming the holder, broken with
// force over the socket and recorded), the CLI saying which scope is missing, a listener beyond
// loopback refused without TLS, TLS verified against a test CA, and — in a private network
// namespace where 192.0.2.77 is a local but non-loopback address — a remote peer that needs a key
// for every request. The transport is what the server sees of the connection, never configured.
#include <unistd.h>

#include <fstream>
#include <iterator>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "colorlab/client/api_client.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/testing/daemon.hpp"
#include "colorlab/testing/process.hpp"
#include "colorlab/testing/temp_dir.hpp"

using colorlab::client::ApiClient;
using colorlab::client::ApiError;
using colorlab::client::Endpoint;
using colorlab::client::RawResponse;
using colorlab::testing::DaemonProcess;
using colorlab::testing::Process;
using colorlab::testing::TempDir;
using colorlab::testing::bin_path;
using colorlab::testing::run_command;
using nlohmann::json;

namespace {

std::filesystem::path write_config(const TempDir& dir, const std::string& text) {
  auto path = dir / "colorlabd.toml";
  std::ofstream(path) << text;
  return path;
}

ApiClient tcp(const DaemonProcess& d, const std::string& key = {}) {
  return ApiClient(Endpoint::from_url(d.url())).with_api_key(key);
}

ApiClient unix_socket(const DaemonProcess& d) {
  Endpoint e;
  e.unix_socket = d.unix_socket();
  return ApiClient(e);
}

// status and parsed body of any request
std::pair<int, json> call(const ApiClient& api, const std::string& method, const std::string& target,
                          const json& body = nullptr, RawResponse* raw = nullptr) {
  auto r = api.request(method, target, body.is_null() ? std::string() : body.dump());
  if (raw) *raw = r;
  return {r.status, json::parse(r.body, nullptr, false)};
}

struct Key {
  std::string id, secret;
};

Key create_key(const ApiClient& admin, const std::string& name, const std::string& scope) {
  RawResponse raw;
  auto [status, body] = call(admin, "POST", "/v1/keys", {{"name", name}, {"scope", scope}}, &raw);
  EXPECT_EQ(status, 201) << body;
  EXPECT_EQ(raw.headers["Cache-Control"], "no-store");
  EXPECT_EQ(body["scope"], scope);
  return {body["id"], body["secret"]};
}

std::string file_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

TEST(access_daemon, LoopbackReadsAreOpenControlNeedsAKeyTheUnixSocketHasEveryScope) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_config(dir, "[queue]\nautostart = false\n"));
  auto open = tcp(daemon);
  EXPECT_EQ(call(open, "GET", "/v1").first, 200);
  EXPECT_EQ(call(open, "GET", "/v1/runs").first, 200);
  EXPECT_EQ(call(open, "GET", "/v1/control").first, 200);

  RawResponse raw;
  auto [status, body] = call(open, "POST", "/v1/queue/start", json::object(), &raw);
  EXPECT_EQ(status, 401) << body;
  EXPECT_EQ(raw.content_type, "application/problem+json");
  EXPECT_EQ(raw.headers["WWW-Authenticate"].rfind("Bearer", 0), 0u) << raw.headers["WWW-Authenticate"];
  EXPECT_EQ(body["code"], "key-required");
  EXPECT_EQ(body["required_scope"], "control");
  EXPECT_NE(body["detail"].get<std::string>().find("loopback"), std::string::npos) << body;
  EXPECT_EQ(call(open, "GET", "/v1/keys").first, 401);

  // The socket's file permissions are its guard: owner and group only.
  auto perms = std::filesystem::status(daemon.unix_socket()).permissions();
  EXPECT_EQ(perms & std::filesystem::perms::all,
            std::filesystem::perms::owner_read | std::filesystem::perms::owner_write |
                std::filesystem::perms::group_read | std::filesystem::perms::group_write);
  auto local = unix_socket(daemon);
  EXPECT_EQ(call(local, "POST", "/v1/queue/start", json::object()).first, 200);
  EXPECT_EQ(call(local, "POST", "/v1/queue/stop", json::object()).first, 200);
  EXPECT_EQ(call(local, "GET", "/v1/keys").first, 200);
}

TEST(access_daemon, EachScopeGetsTheRightAnswerForEachRouteClassAndARevokedKeyIs401) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_config(dir, "[queue]\nautostart = false\n"));
  auto local = unix_socket(daemon);
  std::map<std::string, Key> keys;
  for (const char* scope : {"read", "control", "admin"}) keys[scope] = create_key(local, std::string("k-") + scope, scope);

  struct Case {
    std::string method, target;
    std::map<std::string, int> expected;  // by scope
  };
  std::vector<Case> cases{
      {"GET", "/v1/runs", {{"read", 200}, {"control", 200}, {"admin", 200}}},
      {"POST", "/v1/queue/stop", {{"read", 403}, {"control", 200}, {"admin", 200}}},
      {"POST", "/v1/executions/no-such-execution/abort", {{"read", 403}, {"control", 404}, {"admin", 404}}},
      {"POST", "/v1/requests/no-such-request", {{"read", 403}, {"control", 400}, {"admin", 400}}},
      {"GET", "/v1/keys", {{"read", 403}, {"control", 403}, {"admin", 200}}},
  };
  for (const auto& c : cases) {
    for (const auto& [scope, key] : keys) {
      auto [status, body] = call(tcp(daemon, key.secret), c.method, c.target,
                                 c.method == "POST" ? json::object() : json(nullptr));
      EXPECT_EQ(status, c.expected.at(scope)) << c.method << " " << c.target << " with a " << scope << " key: " << body;
      if (status == 403) {
        std::string needed = c.target == "/v1/keys" ? "admin" : "control";
        EXPECT_EQ(body["required_scope"], needed) << body;
        EXPECT_EQ(body["scope"], scope) << body;
      }
    }
  }

  // GET /v1/control tells each caller its own scope (the web console shows itself read-only by it).
  for (const auto& [scope, key] : keys) {
    auto [control_status, control] = call(tcp(daemon, key.secret), "GET", "/v1/control");
    ASSERT_EQ(control_status, 200) << control;
    EXPECT_EQ(control["scope"], scope) << control;
  }
  EXPECT_EQ(call(tcp(daemon, ""), "GET", "/v1/control").second["scope"], "read");  // keyless loopback reads
  EXPECT_EQ(call(local, "GET", "/v1/control").second["scope"], "admin");           // the Unix socket may do all

  // An admin key revokes the control key over TCP; from then on the control key gets 401 even for reads.
  auto [revoked_status, revoked] = call(tcp(daemon, keys["admin"].secret), "DELETE", "/v1/keys/" + keys["control"].id);
  ASSERT_EQ(revoked_status, 200) << revoked;
  EXPECT_TRUE(revoked["revoked"].get<bool>());
  RawResponse raw;
  auto [status, body] = call(tcp(daemon, keys["control"].secret), "GET", "/v1/runs", nullptr, &raw);
  EXPECT_EQ(status, 401) << body;
  EXPECT_EQ(body["code"], "key-revoked");
  EXPECT_NE(raw.headers["WWW-Authenticate"].find("invalid_token"), std::string::npos);
  // An unknown key is no better than none.
  EXPECT_EQ(call(tcp(daemon, "clk_" + std::string(43, 'A')), "GET", "/v1/runs").first, 401);

  // The list says who exists and what each may do, never a secret.
  auto [list_status, list] = call(local, "GET", "/v1/keys");
  ASSERT_EQ(list_status, 200);
  ASSERT_EQ(list["items"].size(), 3u);
  for (const auto& [scope, key] : keys) EXPECT_EQ(list.dump().find(key.secret.substr(4)), std::string::npos);
}

TEST(access_daemon, KeysAreStoredHashedTheSecretIsInNoFileOfTheStateDirectory) {
  TempDir dir;
  std::string secret;
  {
    DaemonProcess daemon(dir / "state", write_config(dir, "[queue]\nautostart = false\n"));
    secret = create_key(unix_socket(daemon), "auditor", "read").secret;
    EXPECT_EQ(call(tcp(daemon, secret), "GET", "/v1/runs").first, 200);
    // While the daemon runs (database and write-ahead log), and again after it stopped (checkpointed).
    for (const auto& f : std::filesystem::recursive_directory_iterator(dir / "state")) {
      if (f.is_regular_file()) {
        EXPECT_EQ(file_bytes(f.path()).find(secret.substr(4)), std::string::npos) << f.path();
      }
    }
    EXPECT_EQ(daemon.terminate(), 0);
  }
  for (const auto& f : std::filesystem::recursive_directory_iterator(dir / "state")) {
    if (f.is_regular_file()) {
      EXPECT_EQ(file_bytes(f.path()).find(secret.substr(4)), std::string::npos) << f.path();
    }
  }
  // What is stored is the key's SHA-256, as sha256sum computes it.
  auto stored = run_command({"/usr/bin/python3", "-c",
                             "import sqlite3,sys; print(sqlite3.connect(sys.argv[1]).execute("
                             "'select secret_sha256 from api_keys').fetchone()[0])",
                             (dir / "state" / "colorlab.db").string()});
  ASSERT_EQ(stored.exit_code, 0) << stored.err;
  auto sum = run_command({"/bin/sh", "-c", "printf %s '" + secret + "' | sha256sum"});
  EXPECT_EQ(stored.out.substr(0, 64), sum.out.substr(0, 64));
}

TEST(access_daemon, TwoKeysContendForTheControlLock) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_config(dir, "[queue]\nautostart = false\n"));
  auto local = unix_socket(daemon);
  auto anna = tcp(daemon, create_key(local, "anna", "control").secret);
  auto ben = tcp(daemon, create_key(local, "ben", "control").secret);

  auto [taken_status, taken] = call(anna, "POST", "/v1/control/acquire", {{"holder", "anna at the bench"}});
  ASSERT_EQ(taken_status, 200) << taken;
  EXPECT_TRUE(taken["yours"].get<bool>());
  EXPECT_EQ(call(anna, "POST", "/v1/queue/stop", json::object()).first, 200);

  for (const auto& [method, target] : std::vector<std::pair<std::string, std::string>>{
           {"POST", "/v1/queue/stop"}, {"POST", "/v1/control/acquire"}, {"POST", "/v1/control/release"}}) {
    auto [status, body] = call(ben, method, target, json::object());
    EXPECT_EQ(status, 409) << target << ": " << body;
    EXPECT_EQ(body["code"], "control-locked");
    EXPECT_EQ(body["holder"], "anna at the bench");
    EXPECT_NE(body["detail"].get<std::string>().find("anna at the bench"), std::string::npos);
  }
  auto [seen_status, seen] = call(ben, "GET", "/v1/control");
  ASSERT_EQ(seen_status, 200);
  EXPECT_EQ(seen["holder"], "anna at the bench");
  EXPECT_FALSE(seen["yours"].get<bool>());
  EXPECT_EQ(call(ben, "POST", "/v1/control/acquire", {{"force", true}}).first, 403);  // control is not admin

  // The Unix socket is held to the lock too, until it breaks it.
  EXPECT_EQ(call(local, "POST", "/v1/queue/stop", json::object()).first, 409);
  auto [broken_status, broken] = call(local, "POST", "/v1/control/release", {{"force", true}});
  ASSERT_EQ(broken_status, 200) << broken;
  EXPECT_FALSE(broken["held"].get<bool>());
  auto [mine_status, mine] = call(ben, "POST", "/v1/control/acquire", json::object());
  ASSERT_EQ(mine_status, 200) << mine;
  EXPECT_EQ(mine["holder"], "ben");  // the key's name by default

  // The event log has it all, written on the daemon's writer thread after the answers.
  std::vector<std::string> events;
  json log;
  for (int i = 0; i < 100 && events.size() < 3; ++i) {
    events.clear();
    log = call(local, "GET", "/v1/events?topic=control").second;
    for (const auto& e : log["items"]) events.push_back(e["payload"]["event"]);
    if (events.size() < 3) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_EQ(events, (std::vector<std::string>{"acquired", "broken", "acquired"})) << log;
}

TEST(access_daemon, TheCliManagesKeysAndTheLockAndSaysWhichScopeIsMissing) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", write_config(dir, "[queue]\nautostart = false\n"));
  auto over_socket = [&](std::vector<std::string> args) {
    args.insert(args.begin(), {bin_path("colorlab"), "--socket", daemon.unix_socket()});
    return run_command(args);
  };
  auto over_tcp = [&](const std::string& key, std::vector<std::string> args) {
    args.insert(args.begin(), {bin_path("colorlab"), "--url", daemon.url()});
    if (!key.empty()) args.insert(args.begin() + 1, {"--key", key});
    return run_command(args);
  };
  auto created = over_socket({"--json", "keys", "create", "reader", "--scope", "read"});
  ASSERT_EQ(created.exit_code, 0) << created.err;
  std::string read_key = json::parse(created.out)["secret"];
  std::string read_id = json::parse(created.out)["id"];
  auto text = over_socket({"keys", "create", "driver", "--scope", "control"});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("shown only now"), std::string::npos) << text.out;

  auto refused = over_tcp(read_key, {"queue", "start"});
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("403"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("needs the 'control' scope"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("'read'"), std::string::npos) << refused.err;
  auto anonymous = over_tcp("", {"queue", "start"});
  EXPECT_EQ(anonymous.exit_code, 2);
  EXPECT_NE(anonymous.err.find("needs an API key"), std::string::npos) << anonymous.err;
  EXPECT_EQ(over_tcp(read_key, {"status"}).exit_code, 0);

  auto listed = over_socket({"keys", "list"});
  ASSERT_EQ(listed.exit_code, 0) << listed.err;
  EXPECT_NE(listed.out.find("reader"), std::string::npos);
  EXPECT_NE(listed.out.find("driver"), std::string::npos);
  EXPECT_EQ(listed.out.find(read_key.substr(4)), std::string::npos);
  auto revoked = over_socket({"keys", "revoke", read_id});
  ASSERT_EQ(revoked.exit_code, 0) << revoked.err;
  EXPECT_NE(revoked.out.find("REVOKED"), std::string::npos) << revoked.out;
  auto after = over_tcp(read_key, {"status"});
  EXPECT_EQ(after.exit_code, 2);
  EXPECT_NE(after.err.find("revoked"), std::string::npos) << after.err;

  auto acquired = over_socket({"control", "acquire", "--holder", "night shift"});
  ASSERT_EQ(acquired.exit_code, 0) << acquired.err;
  auto status = over_tcp("", {"control", "status"});
  ASSERT_EQ(status.exit_code, 0) << status.err;
  EXPECT_NE(status.out.find("held by 'night shift'"), std::string::npos) << status.out;
  EXPECT_EQ(over_socket({"control", "release"}).exit_code, 0);
  EXPECT_NE(over_socket({"control", "status"}).out.find("free"), std::string::npos);
}

TEST(access_daemon, AListenerBeyondLoopbackWithoutTlsIsRefusedUnlessPlaintextIsAllowed) {
  TempDir dir;
  auto config = write_config(dir, "state_dir = \"state\"\nlisten = \"0.0.0.0:0\"\n");
  Process refused({bin_path("colorlabd"), "--config", config.string()}, dir / "refused.log");
  auto code = refused.wait(std::chrono::seconds(30));
  ASSERT_TRUE(code.has_value()) << "colorlabd kept running on 0.0.0.0 without TLS";
  EXPECT_NE(*code, 0);
  auto log = file_bytes(dir / "refused.log");
  EXPECT_NE(log.find("needs TLS"), std::string::npos) << log;
  EXPECT_FALSE(std::filesystem::exists(dir / "state" / "colorlabd.endpoint"));

  write_config(dir, "state_dir = \"state\"\nlisten = \"0.0.0.0:0\"\n[access]\nallow_plaintext = true\n");
  Process allowed({bin_path("colorlabd"), "--config", config.string()}, dir / "allowed.log");
  EXPECT_NO_THROW(colorlab::testing::wait_for_endpoint(dir / "state", allowed.pid()));
  EXPECT_NE(file_bytes(dir / "allowed.log").find("without TLS"), std::string::npos);
}

namespace {

// A self-signed certificate for `addresses` (its own CA), made by openssl(1).
void make_certificate(const TempDir& dir, const std::string& san) {
  auto r = run_command({"/usr/bin/openssl", "req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:P-256", "-nodes",
                        "-keyout", (dir / "key.pem").string(), "-out", (dir / "cert.pem").string(), "-days", "2",
                        "-subj", "/CN=colorlab test", "-addext", "subjectAltName=" + san});
  ASSERT_EQ(r.exit_code, 0) << r.err;
}

// run_command does not search PATH.
std::string tool(const std::string& name) {
  auto path = colorlab::testing::shell_output("command -v " + name);
  while (!path.empty() && (path.back() == '\n' || path.back() == ' ')) path.pop_back();
  return path;
}

std::string tls_config(const TempDir& dir, const std::string& listen) {
  return "state_dir = \"state\"\nlisten = \"" + listen + "\"\n[access]\ntls_certificate = \"" +
         (dir / "cert.pem").string() + "\"\ntls_private_key = \"" + (dir / "key.pem").string() + "\"\n";
}

}  // namespace

TEST(access_daemon, TlsOnLoopbackIsVerifiedAgainstTheGivenCa) {
  TempDir dir;
  make_certificate(dir, "IP:127.0.0.1");
  Process daemon({bin_path("colorlabd"), "--config", write_config(dir, tls_config(dir, "127.0.0.1:0")).string()},
                 dir / "colorlabd.log");
  auto endpoint = colorlab::testing::wait_for_endpoint(dir / "state", daemon.pid());
  std::string port = std::to_string(endpoint["port"].get<int>());

  auto e = Endpoint::from_url("https://127.0.0.1:" + port);
  e.ca_file = (dir / "cert.pem").string();
  auto [status, body] = call(ApiClient(e), "GET", "/v1");
  EXPECT_EQ(status, 200) << body;
  auto cli = run_command({bin_path("colorlab"), "--url", "https://127.0.0.1:" + port, "--cacert",
                          (dir / "cert.pem").string(), "status"});
  EXPECT_EQ(cli.exit_code, 0) << cli.err;

  // Not trusted without the CA; not this server under a name the certificate does not hold.
  try {
    ApiClient(Endpoint::from_url("https://127.0.0.1:" + port)).get("/v1");
    FAIL() << "a certificate no trusted CA issued was accepted";
  } catch (const colorlab::Error& err) {
    EXPECT_NE(std::string(err.what()).find("certificate verify failed"), std::string::npos) << err.what();
    EXPECT_NE(err.hint().find("--cacert"), std::string::npos);
  }
  // localhost reaches the same server, but the certificate names only 127.0.0.1.
  auto wrong = run_command({bin_path("colorlab"), "--url", "https://localhost:" + port, "--cacert",
                            (dir / "cert.pem").string(), "status"});
  EXPECT_EQ(wrong.exit_code, 1) << wrong.out;
  EXPECT_NE(wrong.err.find("certificate verify failed"), std::string::npos) << wrong.err;
  // Plain HTTP to the TLS port gets no answer.
  EXPECT_THROW(ApiClient(Endpoint::from_url("http://127.0.0.1:" + port), std::chrono::seconds(5)).get("/v1"),
               colorlab::Error);
}

// A peer that is not loopback, for real: in a private network namespace (unshare -rn), 192.0.2.77
// (TEST-NET-1) is put on lo, and the daemon listens there with TLS. The client connects from that
// address, so the server sees a remote peer — the same code path as a laptop across the lab.
TEST(access_daemon, ARemotePeerNeedsAKeyForEveryRequest) {
  const std::string address = "192.0.2.77";
  if (!std::getenv("COLORLAB_TEST_IN_NETNS")) {
    if (!colorlab::testing::on_path("unshare") || !colorlab::testing::on_path("ip")) {
      GTEST_SKIP() << "needs unshare and ip (util-linux, iproute2) for a private network namespace";
    }
    if (run_command({tool("unshare"), "-rn", "true"}).exit_code != 0) {
      GTEST_SKIP() << "unprivileged user and network namespaces are disabled on this host";
    }
    char self[4096] = {};
    ASSERT_GT(::readlink("/proc/self/exe", self, sizeof self - 1), 0);
    auto r = run_command({tool("unshare"), "-rn", "env", "COLORLAB_TEST_IN_NETNS=1", self,
                          "--gtest_filter=access_daemon.ARemotePeerNeedsAKeyForEveryRequest"},
                         std::chrono::seconds(120));
    EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
    EXPECT_NE(r.out.find("[  PASSED  ] 1 test"), std::string::npos) << r.out;
    return;
  }
  ASSERT_EQ(run_command({tool("ip"), "link", "set", "lo", "up"}).exit_code, 0);
  auto added = run_command({tool("ip"), "addr", "add", address + "/32", "dev", "lo"});
  ASSERT_EQ(added.exit_code, 0) << added.err;

  TempDir dir;
  make_certificate(dir, "IP:" + address);
  Process daemon({bin_path("colorlabd"), "--config", write_config(dir, tls_config(dir, address + ":0")).string()},
                 dir / "colorlabd.log");
  auto endpoint = colorlab::testing::wait_for_endpoint(dir / "state", daemon.pid());
  Endpoint local;
  local.unix_socket = endpoint["unix_socket"];
  auto remote = Endpoint::from_url("https://" + address + ":" + std::to_string(endpoint["port"].get<int>()));
  remote.ca_file = (dir / "cert.pem").string();

  RawResponse raw;
  auto [status, body] = call(ApiClient(remote), "GET", "/v1/runs", nullptr, &raw);
  EXPECT_EQ(status, 401) << body;
  EXPECT_EQ(body["code"], "key-required");
  EXPECT_EQ(raw.headers["WWW-Authenticate"].rfind("Bearer", 0), 0u);
  EXPECT_EQ(call(ApiClient(remote), "GET", "/v1").first, 401);
  // The web console's page itself holds no data, and a browser cannot attach a key to loading it:
  // served to anyone; every datum it then asks for goes through the API with the key.
  auto page = call(ApiClient(remote), "GET", "/", nullptr, &raw);
  EXPECT_EQ(page.first, 200) << raw.body.substr(0, 300);
  EXPECT_EQ(raw.content_type.rfind("text/html", 0), 0u) << raw.content_type;

  auto reader = create_key(ApiClient(local), "remote reader", "read");
  auto driver = create_key(ApiClient(local), "remote driver", "control");
  EXPECT_EQ(call(ApiClient(remote).with_api_key(reader.secret), "GET", "/v1/runs").first, 200);
  EXPECT_EQ(call(ApiClient(remote).with_api_key(reader.secret), "POST", "/v1/queue/stop", json::object()).first, 403);
  EXPECT_EQ(call(ApiClient(remote).with_api_key(driver.secret), "POST", "/v1/queue/stop", json::object()).first, 200);
  EXPECT_EQ(call(ApiClient(remote).with_api_key(driver.secret), "GET", "/v1/keys").first, 403);
}
