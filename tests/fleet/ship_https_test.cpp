// S3 over HTTPS where the lab configures it (issue 22, "Secure links"): nginx terminates TLS in front of the test's
// Swift s3api on 127.0.0.1 with certificates from a throwaway CA made with the openssl CLI. colorlab-ship, given the
// https:// endpoint and the CA in [ship] s3_ca_file, ships a bench's runs through it, and colorlab-central, with the
// same in [central], reads a blob back over HTTPS. A certificate another CA signed (and the test CA without
// s3_ca_file) fails with an error saying the certificate was not verified, and nothing is marked shipped. Real
// PostgreSQL 15 and Swift; fails, not skips, without them or nginx (scripts/setup.sh installs them).
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <fstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "colorlab/fleet/config.hpp"
#include "colorlab/fleet/s3.hpp"
#include "colorlab/testing/process.hpp"
#include "fleet_servers.hpp"
#include "sim_bench.hpp"
#include "web_tls_servers.hpp"

namespace fs = std::filesystem;
using namespace colorlab;
namespace ct = colorlab::testing;
using namespace colorlab::fleet_test;
using nlohmann::json;
using protocol::ExecutionStatus;

namespace {

SharedServers& servers() { return web_tls_servers(); }

void sh(const std::string& cmd) {
  auto r = ct::run_command({"/bin/sh", "-c", cmd}, std::chrono::seconds(60));
  if (r.exit_code != 0) throw std::runtime_error(cmd + ": " + r.out + r.err);
}

// The lab's CA and a server certificate for 127.0.0.1 it signed; an unrelated CA and a certificate for the same
// address that one signed (what a wrong or intercepted store would present).
void make_pki(const fs::path& dir) {
  fs::create_directories(dir);
  const std::string p = dir.string();
  for (const char* ca : {"ca", "other-ca"}) {
    sh("cd " + p + " && openssl req -x509 -newkey rsa:2048 -nodes -days 2 -subj /CN=colorlab-test-" + std::string(ca) +
       " -keyout " + ca + ".key -out " + ca + ".pem 2>&1");
  }
  sh("cd " + p + " && printf 'subjectAltName=IP:127.0.0.1,DNS:localhost\\n' > san.ext");
  for (const auto& [cert, ca] : {std::pair<std::string, std::string>{"store", "ca"}, {"rogue", "other-ca"}}) {
    sh("cd " + p + " && openssl req -newkey rsa:2048 -nodes -subj /CN=127.0.0.1 -keyout " + cert + ".key -out " + cert +
       ".csr 2>&1 && openssl x509 -req -in " + cert + ".csr -CA " + ca + ".pem -CAkey " + ca + ".key -CAcreateserial " +
       "-days 2 -extfile san.ext -out " + cert + ".crt 2>&1");
  }
}

// nginx as the lab's TLS front to Swift: one listener with the store's certificate, one with the rogue's. The Host
// header goes through unchanged (the SigV4 signature covers it) and bodies stream both ways unbuffered.
class TlsFront {
 public:
  TlsFront(const fs::path& dir, const fs::path& pki, const std::string& upstream) : dir_(dir) {
    fs::create_directories(dir / "logs");
    good_ = free_port_run(1);
    do rogue_ = free_port_run(1);
    while (rogue_ == good_);
    auto server = [&](int port, const std::string& cert, const std::string& log) {
      return "  server {\n    listen 127.0.0.1:" + std::to_string(port) + " ssl;\n    ssl_certificate " +
             (pki / (cert + ".crt")).string() + ";\n    ssl_certificate_key " + (pki / (cert + ".key")).string() +
             ";\n    access_log " + (dir / "logs" / log).string() + ";\n    location / {\n      proxy_pass " + upstream +
             ";\n      proxy_set_header Host $http_host;\n      proxy_http_version 1.1;\n"
             "      proxy_request_buffering off;\n      proxy_buffering off;\n    }\n  }\n";
    };
    const std::string tmp = (dir / "tmp").string();
    fs::create_directories(tmp);
    std::ofstream(dir / "nginx.conf")
        << "daemon off;\nmaster_process off;\npid " << (dir / "nginx.pid").string() << ";\nerror_log "
        << (dir / "logs" / "error.log").string() << " warn;\nevents { worker_connections 64; }\nhttp {\n"
        << "  client_max_body_size 0;\n  client_body_temp_path " << tmp << "/body;\n  proxy_temp_path " << tmp
        << "/proxy;\n  fastcgi_temp_path " << tmp << "/fastcgi;\n  uwsgi_temp_path " << tmp << "/uwsgi;\n"
        << "  scgi_temp_path " << tmp << "/scgi;\n"
        << server(good_, "store", "store.log") << server(rogue_, "rogue", "rogue.log") << "}\n";
    process_ = std::make_unique<ct::Process>(
        std::vector<std::string>{"/usr/sbin/nginx", "-p", dir.string(), "-e", (dir / "logs" / "error.log").string(),
                                 "-c", (dir / "nginx.conf").string()},
        dir / "nginx.stderr");
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!accepts(good_) || !accepts(rogue_)) {
      if (!process_->running() || std::chrono::steady_clock::now() > deadline) {
        throw std::runtime_error("nginx did not listen: " + read_all(dir / "nginx.stderr") +
                                 read_all(dir / "logs" / "error.log"));
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  std::string endpoint() const { return "https://127.0.0.1:" + std::to_string(good_); }
  std::string rogue_endpoint() const { return "https://127.0.0.1:" + std::to_string(rogue_); }
  std::string store_log() const { return read_all(dir_ / "logs" / "store.log"); }
  // nginx writes a request's access-log line after the answer's last byte left, so the client can be done
  // first: wait (bounded) for the line rather than read the log at once.
  std::string store_log_with(const std::string& needle) const {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(15);
    std::string log = store_log();
    while (log.find(needle) == std::string::npos && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      log = store_log();
    }
    return log;
  }

 private:
  fs::path dir_;
  int good_ = 0, rogue_ = 0;
  std::unique_ptr<ct::Process> process_;
};

// run_command's output ends with a line break curl did not write.
std::string trimmed(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  return s;
}

ct::RunResult ship(const fs::path& config) {
  return ct::run_command({ct::bin_path("colorlab-ship"), "--config", config.string(), "once"}, std::chrono::seconds(120));
}

// The bench's TOML aimed at `endpoint`, with `s3_ca_file` when not empty.
fs::path configure(SimBench& bench, ShipTarget t, const std::string& endpoint, const fs::path& ca) {
  t.s3_endpoint = endpoint;
  const fs::path file = bench.write_config(t);
  if (!ca.empty()) std::ofstream(file, std::ios::app) << "s3_ca_file = \"" << ca.string() << "\"\n";
  return file;
}

TEST(ShipHttps, ShipsAndReadsBackThroughATlsFrontWithTheLabsCa) {
  const std::string missing = missing_tools() + (fs::exists("/usr/sbin/nginx") ? "" : " nginx-light") +
                              (ct::on_path("openssl") ? "" : " openssl");
  if (!missing.empty()) FAIL() << "this test needs:" << missing << " (scripts/setup.sh installs them)";
  const auto t0 = std::chrono::steady_clock::now();
  auto& s = servers();
  const std::string name = s.fresh_for_current_test();
  const fs::path dir = s.root / name;
  const ShipTarget target{s.pg->conninfo(name), s.swift->endpoint(), name, SwiftServer::kAccessKey,
                          SwiftServer::kSecretKey};
  make_pki(dir / "pki");
  TlsFront front(dir / "nginx", dir / "pki", s.swift->endpoint());
  const fs::path ca = dir / "pki" / "ca.pem";
  const auto t1 = std::chrono::steady_clock::now();

  SimBench bench(dir / "bench", "bench-https", 71);
  std::vector<std::string> runs;
  for (int i = 0; i < 2; ++i) runs.push_back(bench.run_campaign(ExecutionStatus::finished_ok, 12, 4));
  fleet::ShipConfig bench_config;
  bench_config.state_dir = bench.state_dir();
  const fs::path position = bench_config.shipped_position_file();
  auto shipped_runs = [&] {
    if (s.pg->psql(name, "SELECT count(*) FROM pg_tables WHERE tablename = 'runs'") == "0") return std::string("0");
    return s.pg->psql(name, "SELECT count(*) FROM runs");
  };

  // A store whose certificate another CA signed: refused before a byte is sent, saying why, nothing shipped.
  auto r = ship(configure(bench, target, front.rogue_endpoint(), ca));
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.err.find("TLS certificate was not verified against s3_ca_file " + ca.string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("hint: s3_ca_file must name the CA certificate"), std::string::npos) << r.err;
  EXPECT_EQ(shipped_runs(), "0");
  EXPECT_EQ(fleet::read_shipped_position(position), 0);
  // The lab's CA is no system CA: without s3_ca_file the right store is refused too.
  r = ship(configure(bench, target, front.endpoint(), {}));
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.err.find("TLS certificate was not verified against the system's CA certificates"), std::string::npos)
      << r.err;
  EXPECT_EQ(shipped_runs(), "0");
  EXPECT_EQ(fleet::read_shipped_position(position), 0);
  EXPECT_EQ(front.store_log(), "") << "no request may have passed the TLS front";
  // A CA file for a plain-HTTP endpoint is a configuration mistake, said as one.
  r = ship(configure(bench, target, s.swift->endpoint(), ca));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("s3_ca_file is for an https:// s3_endpoint"), std::string::npos) << r.err;

  // The lab's configuration: the https endpoint and its CA. Every blob went through the TLS front.
  r = ship(configure(bench, target, front.endpoint(), ca));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(shipped_runs(), "2");
  EXPECT_GT(fleet::read_shipped_position(position), 0);
  const std::string blobs = s.pg->psql(name, "SELECT count(*) FROM run_blobs");
  EXPECT_EQ(blobs, "6") << "three frames a run";
  const std::string log = front.store_log_with("\"PUT /" + name + "/sha256/");
  EXPECT_NE(log.find("\"PUT /" + name + "/sha256/"), std::string::npos) << log;
  const auto t2 = std::chrono::steady_clock::now();

  // colorlab-central reads the bucket over HTTPS with the same CA: a blob comes back whole and hashes to its name.
  auto start_central = [&](const std::string& sub, const std::string& endpoint) {
    const fs::path c = dir / sub;
    fs::create_directories(c);
    std::ofstream(c / "s3-access-key") << target.access_key << "\n";
    std::ofstream(c / "s3-secret-key") << target.secret_key << "\n";
    std::ofstream(c / "central.toml") << "state_dir = \"" << (c / "state").string() << "\"\n[central]\n"
                                      << "listen = \"127.0.0.1\"\nport = 0\nthreads = 2\npostgres = \"" << target.postgres
                                      << "\"\ns3_endpoint = \"" << endpoint << "\"\nbucket = \"" << name << "\"\n"
                                      << "access_key_file = \"s3-access-key\"\nsecret_key_file = \"s3-secret-key\"\n"
                                      << "s3_ca_file = \"" << ca.string() << "\"\n";
    auto p = std::make_unique<ct::Process>(
        std::vector<std::string>{ct::bin_path("colorlab-central"), "--config", (c / "central.toml").string(), "serve"},
        c / "central.log");
    auto line = p->read_line(std::chrono::seconds(60));
    if (!line) throw std::runtime_error("colorlab-central did not start: " + read_all(c / "central.log"));
    return std::pair{std::move(p), json::parse(*line)["url"].get<std::string>()};
  };
  auto [central, url] = start_central("central", front.endpoint());
  const std::string sha = s.pg->psql(name, "SELECT sha256 FROM run_blobs WHERE run_id = '" + runs[1] + "' LIMIT 1");
  ASSERT_EQ(sha.size(), 64u);
  const fs::path got = dir / "blob.out";
  auto fetched = ct::run_command({"/usr/bin/curl", "-s", "-w", "%{http_code}", "-o", got.string(),
                                  url + "/v1/blobs/" + sha},
                                 std::chrono::seconds(60));
  EXPECT_EQ(trimmed(fetched.out), "200") << read_all(got).substr(0, 400);
  EXPECT_EQ(fleet::sha256_hex(read_all(got)), sha);
  EXPECT_NE(front.store_log_with("\"GET /" + name + "/sha256/" + sha).find("\"GET /" + name + "/sha256/" + sha),
            std::string::npos)
      << "read through the front";

  // Central aimed at the rogue certificate answers with the reason, not with bytes.
  auto [rogue_central, rogue_url] = start_central("central-rogue", front.rogue_endpoint());
  auto refused = ct::run_command({"/usr/bin/curl", "-s", "-w", "\n%{http_code}", rogue_url + "/v1/blobs/" + sha},
                                 std::chrono::seconds(60));
  EXPECT_NE(refused.out.find("TLS certificate was not verified"), std::string::npos) << refused.out;
  const std::string answer = trimmed(refused.out);
  const auto nl = answer.rfind('\n');
  EXPECT_EQ(nl == std::string::npos ? "" : answer.substr(nl + 1), "502") << refused.out;
  const auto t3 = std::chrono::steady_clock::now();
  auto sec = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
  std::cerr << "ship https: servers, CA and nginx " << sec(t0, t1) << " s, shipping (3 refused, 1 through TLS) "
            << sec(t1, t2) << " s, central over HTTPS " << sec(t2, t3) << " s\n";
}

}  // namespace
