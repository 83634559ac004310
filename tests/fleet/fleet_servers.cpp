#include "fleet_servers.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <pwd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cctype>
#include <csignal>
#include <fstream>
#include <iostream>
#include <iterator>
#include <random>
#include <stdexcept>
#include <thread>

#include "colorlab/core/error.hpp"
#include "colorlab/fleet/s3.hpp"
#include "gtest/gtest.h"

namespace colorlab::fleet_test {

namespace fs = std::filesystem;
using clock_type = std::chrono::steady_clock;

namespace {

constexpr const char* kPgBin = "/usr/lib/postgresql/15/bin";

sockaddr_in loopback(int port) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  return a;
}

bool port_free(int port) {
  int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  const sockaddr_in a = loopback(port);
  bool ok = ::bind(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a) == 0;
  ::close(fd);
  return ok;
}

std::string quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

double seconds_since(clock_type::time_point t0) {
  return std::chrono::duration<double>(clock_type::now() - t0).count();
}

}  // namespace

int free_port_run(int count) {
  std::mt19937 rng(std::random_device{}());
  // Below Linux's ephemeral range (32768–60999 by default): a port the tests' own outgoing connections can take as
  // their source port would make a restarted listener (socat, a server) fail to bind.
  std::uniform_int_distribution<int> pick(20000, 32000);
  for (int attempt = 0; attempt < 200; ++attempt) {
    int base = pick(rng);
    bool all = true;
    for (int i = 0; i < count && all; ++i) all = port_free(base + i);
    if (all) return base;
  }
  throw std::runtime_error("no run of free ports on 127.0.0.1");
}

bool accepts(int port) {
  int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  const sockaddr_in a = loopback(port);
  bool ok = ::connect(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a) == 0;
  ::close(fd);
  return ok;
}

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

std::string missing_tools() {
  std::string missing;
  if (!fs::exists(fs::path(kPgBin) / "initdb") || !fs::exists(fs::path(kPgBin) / "pg_ctl")) missing += " postgresql-15";
  if (!testing::on_path("psql")) missing += " postgresql-client-15";
  for (const char* t : {"swift-proxy-server", "swift-object-server", "swift-container-server", "swift-account-server",
                        "swift-ring-builder"}) {
    if (!testing::on_path(t)) {
      missing += " swift swift-proxy swift-object swift-container swift-account";
      break;
    }
  }
  if (!testing::on_path("memcached")) missing += " memcached";
  return missing;
}

PostgresServer::PostgresServer(const fs::path& dir) : dir_(dir) {}

PostgresServer::~PostgresServer() {
  if (initialised_) {
    testing::shell_output(as_owner(std::string(kPgBin) + "/pg_ctl -D " + quote(dir_ / "data") + " -m immediate stop") +
                          " >/dev/null 2>&1");
  }
  std::error_code ec;
  fs::remove_all(dir_, ec);
}

std::string PostgresServer::as_owner(const std::string& command) const {
  // initdb and postgres refuse to run as root.
  if (::geteuid() == 0) return "runuser -u postgres -- " + command;
  return command;
}

void PostgresServer::start() {
  auto t0 = clock_type::now();
  if (!initialised_) {
    fs::create_directories(dir_);
    if (::geteuid() == 0) {
      passwd* pw = ::getpwnam("postgres");
      if (!pw) throw std::runtime_error("no 'postgres' user: install postgresql-15");
      if (::chown(dir_.c_str(), pw->pw_uid, pw->pw_gid) != 0) throw std::runtime_error("cannot chown " + dir_.string());
    }
    port_ = free_port_run(1);
    // --no-sync only skips initdb's own flush of the template files; the server runs with fsync on.
    auto r = testing::run_command({"/bin/sh", "-c",
                                   as_owner(std::string(kPgBin) + "/initdb -D " + quote(dir_ / "data") +
                                            " -A trust -U postgres -E UTF8 --locale=C --no-sync") +
                                       " 2>&1"},
                                  std::chrono::seconds(120));
    if (r.exit_code != 0) throw std::runtime_error("initdb failed: " + r.out + r.err);
    initialised_ = true;
  }
  const std::string opts = "-p " + std::to_string(port_) + " -k " + dir_.string() +
                           " -c listen_addresses=127.0.0.1 -c fsync=on -c max_connections=40";
  auto r = testing::run_command(
      {"/bin/sh", "-c",
       as_owner(std::string(kPgBin) + "/pg_ctl -D " + quote(dir_ / "data") + " -w -t 120 -l " +
                quote(dir_ / "server.log") + " -o " + quote(opts) + " start") +
           " 2>&1"},
      std::chrono::seconds(150));
  if (r.exit_code != 0) throw std::runtime_error("pg_ctl start failed: " + r.out + r.err);
  if (start_seconds == 0) start_seconds = seconds_since(t0);
}

void PostgresServer::stop_immediate() {
  auto r = testing::run_command(
      {
          "/bin/sh",
          "-c",
          as_owner(std::string(kPgBin) + "/pg_ctl -D " + quote(dir_ / "data") + " -m immediate -w stop") +
              " 2>&1",
      },
      std::chrono::seconds(60));
  if (r.exit_code != 0) throw std::runtime_error("pg_ctl stop failed: " + r.out + r.err);
}

std::string PostgresServer::conninfo(const std::string& dbname) const {
  return "host=127.0.0.1 port=" + std::to_string(port_) + " user=postgres dbname=" + dbname + " connect_timeout=10";
}

std::string PostgresServer::psql(const std::string& dbname, const std::string& sql) const {
  auto r = testing::run_command({"/usr/bin/psql", "-X", "-q", "-A", "-t", "-v", "ON_ERROR_STOP=1", "-d",
                                 conninfo(dbname), "-c", sql},
                                std::chrono::seconds(60));
  if (r.exit_code != 0) throw std::runtime_error("psql failed (" + sql + "): " + r.err);
  std::string out = r.out;
  auto nl = out.find('\n');
  if (nl != std::string::npos) out.resize(nl);
  return out;
}

SwiftServer::SwiftServer(const fs::path& dir) : dir_(dir) {
  port_ = free_port_run(5);
  auto t0 = clock_type::now();
  fs::create_directories(dir_);
  // setsid: the script and every server it starts form one process group, stopped together.
  process_ = std::make_unique<testing::Process>(
      std::vector<std::string>{"/usr/bin/setsid", "/bin/bash",
                               std::string(COLORLAB_SOURCE_DIR) + "/tests/fleet/swift_aio.sh", dir_.string(),
                               std::to_string(port_)},
      dir_ / "swift.log");
  try {
    create_bucket("probe");
  } catch (...) {
    stop();
    throw;
  }
  start_seconds = seconds_since(t0);
}

SwiftServer::~SwiftServer() { stop(); }

void SwiftServer::stop() {
  if (!process_) return;
  const pid_t group = process_->pid();
  ::kill(-group, SIGTERM);  // the script's trap stops the servers and memcached
  if (!process_->wait(std::chrono::seconds(30))) ::kill(-group, SIGKILL);
  ::kill(-group, SIGKILL);  // whatever ignored SIGTERM
  process_.reset();
}

void SwiftServer::create_bucket(const std::string& bucket, std::chrono::seconds bound) {
  fleet::S3Client s3(endpoint(), bucket, "us-east-1", {kAccessKey, kSecretKey});
  const auto deadline = clock_type::now() + bound;
  std::string last;
  for (;;) {
    if (!process_->running()) {
      throw std::runtime_error("swift_aio.sh exited; see " + (dir_ / "swift.log").string());
    }
    try {
      s3.create_bucket();
      return;
    } catch (const Error& e) {
      last = e.what();
    }
    if (clock_type::now() > deadline) {
      throw std::runtime_error("Swift did not create bucket '" + bucket + "' within " + std::to_string(bound.count()) +
                               " s: " + last + "; see " + (dir_ / "swift.log").string());
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
}

SharedServers::~SharedServers() {
  swift.reset();
  pg.reset();
  std::error_code ec;
  fs::remove_all(root, ec);  // the Swift storage and the tests' benches
}

std::string SharedServers::fresh_for_current_test() {
  std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  for (auto& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  pg->psql("postgres", "DROP DATABASE IF EXISTS " + name);
  pg->psql("postgres", "CREATE DATABASE " + name);
  swift->create_bucket(name);
  fs::remove_all(root / name);
  return name;
}

SharedServers& shared_servers(const fs::path& scratch, const std::string& pg_name) {
  static SharedServers s;
  if (!s.swift) {  // first use, or a previous start that failed
    s.swift.reset();
    s.pg.reset();
    const std::string pid = std::to_string(::getpid());
    s.root = scratch / pid;
    fs::remove_all(s.root);
    fs::create_directories(s.root);
    s.pg = std::make_unique<PostgresServer>(fs::temp_directory_path() / (pg_name + "-" + pid));
    s.pg->start();
    s.swift = std::make_unique<SwiftServer>(s.root / "swift");
    std::cerr << "fleet servers: PostgreSQL initdb + start " << s.pg->start_seconds << " s, Swift s3api ready in "
              << s.swift->start_seconds << " s\n";
  }
  return s;
}

}  // namespace colorlab::fleet_test
