#pragma once
// Throwaway central servers for the fleet tests, each on 127.0.0.1 under a temporary directory: a PostgreSQL 15
// cluster (initdb; fsync on; as the `postgres` user when the test runs as root, since initdb refuses root) and a
// one-replica Swift with s3api (swift_aio.sh; its storage on disk, since Swift keeps metadata in xattrs).
// missing_tools() names what is not installed: the tests fail on it in CI and skip with the reason elsewhere.
#include <chrono>
#include <filesystem>
#include <memory>
#include <string>

#include "colorlab/testing/process.hpp"

namespace colorlab::fleet_test {

// "" when PostgreSQL 15 and Swift (with memcached) are all installed, else what scripts/setup.sh would install.
std::string missing_tools();

class PostgresServer {
 public:
  explicit PostgresServer(const std::filesystem::path& dir);
  ~PostgresServer();
  void start();
  // `pg_ctl stop -m immediate`: no shutdown checkpoint, the next start runs crash recovery.
  void stop_immediate();
  std::string conninfo(const std::string& dbname) const;
  // Runs SQL through psql; the first column of the first row.
  std::string psql(const std::string& dbname, const std::string& sql) const;
  double start_seconds = 0;  // initdb + first start

 private:
  std::string as_owner(const std::string& command) const;
  std::filesystem::path dir_;
  int port_ = 0;
  bool initialised_ = false;
};

class SwiftServer {
 public:
  explicit SwiftServer(const std::filesystem::path& dir);
  ~SwiftServer();
  std::string endpoint() const { return "http://127.0.0.1:" + std::to_string(port_); }
  static constexpr const char* kAccessKey = "test:tester";
  static constexpr const char* kSecretKey = "testing";
  double start_seconds = 0;  // launch until a bucket could be created

  // Creates a bucket through S3, retrying while the servers come up. The bound only catches a hang: four Python
  // servers take ~4 s on an idle machine and were seen taking 57-84 s beside the team's builds.
  void create_bucket(const std::string& bucket, std::chrono::seconds bound = std::chrono::seconds(300));

 private:
  void stop();
  std::filesystem::path dir_;
  int port_ = 0;
  std::unique_ptr<testing::Process> process_;
};

// A free TCP port on 127.0.0.1 with `count` consecutive free ports from it.
int free_port_run(int count);

// Whether a server accepts TCP connections on 127.0.0.1:`port` yet.
bool accepts(int port);

// A file's bytes ("" when it cannot be read: a log not written yet).
std::string read_all(const std::filesystem::path& p);

// The PostgreSQL and Swift one fleet test program shares: started on first use (again after a start that failed)
// with their scratch under `scratch`/<pid> — under the build tree, on disk, since Swift keeps metadata in extended
// attributes, which tmpfs lacks — and removed at exit with everything the tests put there.
struct SharedServers {
  std::filesystem::path root;
  std::unique_ptr<PostgresServer> pg;
  std::unique_ptr<SwiftServer> swift;
  ~SharedServers();
  // A fresh database and bucket named after the running gtest test (lower case), and its empty folder under
  // root; returns the name.
  std::string fresh_for_current_test();
};
// `pg_name` names PostgreSQL's cluster directory under the system's temporary directory (its socket path must stay
// short).
SharedServers& shared_servers(const std::filesystem::path& scratch, const std::string& pg_name);

}  // namespace colorlab::fleet_test
