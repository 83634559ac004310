#pragma once
// colorlab-central's settings: its own TOML (docs/fleet.md, "The central read API"). The central PostgreSQL and
// bucket the benches ship into, where it listens, and its state directory (its API keys only: everything it
// serves is in PostgreSQL and the bucket). Credentials are named by file, as for colorlab-ship.
#include <filesystem>
#include <string>

namespace colorlab::fleet {

struct CentralConfig {
  std::filesystem::path state_dir = "/var/lib/colorlab-central";
  std::string listen = "127.0.0.1";
  unsigned short port = 8766;
  unsigned threads = 4;  // HTTP pool threads; as many PostgreSQL connections at most
  std::string postgres;
  std::string s3_endpoint;
  std::string bucket;
  std::string region = "us-east-1";
  std::filesystem::path access_key_file;  // a key that may GET objects; first line, never logged
  std::filesystem::path secret_key_file;
  std::filesystem::path s3_ca_file;       // an https:// store's CA (PEM); empty: the system's CAs
  std::filesystem::path tls_certificate;  // both set: the listener speaks TLS
  std::filesystem::path tls_private_key;
  bool allow_plaintext = false;  // beyond loopback without TLS (keys would cross in the clear)

  // The API keys (colorlabd's own key table, the same hashes and checks): colorlab-central keys ...
  std::filesystem::path keys_database() const { return state_dir / "central-keys.db"; }
};

// Error{bad_parameter} naming the file, line and key for anything missing, malformed or unknown.
CentralConfig load_central_config(const std::filesystem::path& toml_file);

}  // namespace colorlab::fleet
