#include "colorlab/fleet/config.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <string>

#include <toml++/toml.h>

#include "colorlab/core/error.hpp"

namespace colorlab::fleet {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void bad(const fs::path& file, const toml::source_region& where, const std::string& what) {
  throw Error(ErrorClass::bad_parameter, file.string() + ":" + std::to_string(where.begin.line) + ": " + what,
              "see docs/fleet.md");
}

std::string need_string(const fs::path& file, const toml::node& node, const std::string& key) {
  auto v = node.value<std::string>();
  if (!v || v->empty()) bad(file, node.source(), "ship." + key + " must be a non-empty string");
  return *v;
}

void fsync_path(const fs::path& p, int flags) {
  int fd = ::open(p.c_str(), flags | O_CLOEXEC);
  if (fd < 0) throw Error(ErrorClass::io_error, "cannot open " + p.string() + " to sync it");
  bool ok = ::fsync(fd) == 0;
  ::close(fd);
  if (!ok) throw Error(ErrorClass::io_error, "cannot fsync " + p.string());
}

}  // namespace

ShipConfig load_ship_config(const fs::path& file) {
  toml::table root;
  try {
    root = toml::parse_file(file.string());
  } catch (const toml::parse_error& e) {
    throw Error(ErrorClass::bad_parameter,
                file.string() + ":" + std::to_string(e.source().begin.line) + ": " + std::string(e.description()),
                "see docs/fleet.md");
  }
  ShipConfig c;
  const fs::path base = file.parent_path();
  auto resolve = [&](const std::string& p) { return fs::path(p).is_absolute() ? fs::path(p) : base / p; };
  if (auto sd = root["state_dir"].value<std::string>()) c.state_dir = resolve(*sd);
  auto ship = root["ship"].as_table();
  if (!ship) {
    throw Error(ErrorClass::bad_parameter, file.string() + " has no [ship] section",
                "add [ship] with bench_id, postgres, s3_endpoint, bucket and the key files (docs/fleet.md)");
  }
  for (const auto& [key, node] : *ship) {
    const std::string k(key.str());
    if (k == "bench_id") c.bench_id = need_string(file, node, k);
    else if (k == "bench_name") c.bench_name = need_string(file, node, k);
    else if (k == "postgres") c.postgres = need_string(file, node, k);
    else if (k == "s3_endpoint") c.s3_endpoint = need_string(file, node, k);
    else if (k == "bucket") c.bucket = need_string(file, node, k);
    else if (k == "region") c.region = need_string(file, node, k);
    else if (k == "access_key_file") c.access_key_file = resolve(need_string(file, node, k));
    else if (k == "secret_key_file") c.secret_key_file = resolve(need_string(file, node, k));
    else if (k == "s3_ca_file") c.s3_ca_file = resolve(need_string(file, node, k));
    else if (k == "batch_runs") {
      auto v = node.value<std::int64_t>();
      if (!v || *v < 1 || *v > 100000) bad(file, node.source(), "ship.batch_runs must be an integer from 1 to 100000");
      c.batch_runs = static_cast<int>(*v);
    } else if (k == "transaction_runs") {
      auto v = node.value<std::int64_t>();
      if (!v || *v < 1 || *v > 10000) bad(file, node.source(), "ship.transaction_runs must be an integer from 1 to 10000");
      c.transaction_runs = static_cast<int>(*v);
    } else if (k == "transaction_measurements") {
      auto v = node.value<std::int64_t>();
      if (!v || *v < 1 || *v > 10000000) {
        bad(file, node.source(), "ship.transaction_measurements must be an integer from 1 to 10000000");
      }
      c.transaction_measurements = *v;
    } else if (k == "backup_keep_daily" || k == "backup_keep_weekly") {
      auto v = node.value<std::int64_t>();
      if (!v || *v < 0 || *v > 3660) bad(file, node.source(), "ship." + k + " must be an integer from 0 to 3660");
      (k == "backup_keep_daily" ? c.backup_keep_daily : c.backup_keep_weekly) = static_cast<int>(*v);
    } else if (k == "interval_s") {
      auto v = node.value<double>();
      if (!v || !(*v >= 0.1 && *v <= 86400)) bad(file, node.source(), "ship.interval_s must be from 0.1 to 86400");
      c.interval_s = *v;
    } else if (k == "stall_timeout_s") {
      auto v = node.value<std::int64_t>();
      if (!v || *v < 1 || *v > 3600) bad(file, node.source(), "ship.stall_timeout_s must be an integer from 1 to 3600");
      c.stall_timeout_s = static_cast<int>(*v);
    } else {
      bad(file, node.source(), "unknown key 'ship." + k + "'");
    }
  }
  const auto& where = ship->source();
  if (c.bench_id.empty()) bad(file, where, "[ship] needs bench_id (unique in the lab, never changed)");
  for (char ch : c.bench_id) {
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '_' || ch == '.')) {
      bad(file, where, "ship.bench_id may hold letters, digits, '-', '_' and '.' only");
    }
  }
  if (c.bench_name.empty()) c.bench_name = c.bench_id;
  if (c.postgres.empty()) bad(file, where, "[ship] needs postgres (a libpq connection string)");
  if (c.s3_endpoint.empty() || c.bucket.empty()) bad(file, where, "[ship] needs s3_endpoint and bucket");
  if (!c.s3_ca_file.empty() && c.s3_endpoint.rfind("https://", 0) != 0) {
    bad(file, where, "ship.s3_ca_file is for an https:// s3_endpoint; '" + c.s3_endpoint + "' is not one");
  }
  if (c.access_key_file.empty() || c.secret_key_file.empty()) {
    bad(file, where, "[ship] needs access_key_file and secret_key_file (the keys themselves never go in this file)");
  }
  return c;
}

namespace {

// Under systemd the units pass each key file as a credential of the file's own name (LoadCredential=), so the
// original can stay root's alone (0600) and only the service sees its copy; run by hand, the configured path.
fs::path credential_or(const fs::path& file) {
  const char* dir = std::getenv("CREDENTIALS_DIRECTORY");
  if (dir == nullptr || *dir == '\0') return file;
  std::error_code ec;
  const fs::path passed = fs::path(dir) / file.filename();
  return fs::is_regular_file(passed, ec) ? passed : file;
}

}  // namespace

std::string read_secret_file(const fs::path& configured, const char* what) {
  const fs::path file = credential_or(configured);
  std::ifstream in(file);
  std::string line;
  if (!in || !std::getline(in, line)) {
    throw Error(ErrorClass::bad_parameter, std::string("cannot read the ") + what + " from " + file.string(),
                "the file must exist, be readable by colorlab-ship and hold the key on its first line");
  }
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
  if (line.empty()) throw Error(ErrorClass::bad_parameter, std::string("the ") + what + " file " + file.string() + " is empty");
  return line;
}

long long read_shipped_position(const fs::path& file) {
  std::ifstream in(file);
  long long v = 0;
  if (!in) return 0;
  if (!(in >> v) || v < 0) throw Error(ErrorClass::bad_data, file.string() + " does not hold a position", "delete it; the next cycle writes it again");
  return v;
}

void write_shipped_position(const fs::path& file, long long position) {
  fs::create_directories(file.parent_path());
  const fs::path tmp = file.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << position << "\n";
    out.flush();
    if (!out) throw Error(ErrorClass::io_error, "cannot write " + tmp.string());
  }
  fsync_path(tmp, O_RDONLY);
  fs::rename(tmp, file);
  fsync_path(file.parent_path(), O_RDONLY | O_DIRECTORY);
}

}  // namespace colorlab::fleet
