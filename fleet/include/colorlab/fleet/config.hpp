#pragma once
// colorlab-ship's settings: the [ship] section of colorlabd's own TOML, plus its state_dir, so one file
// describes the bench (docs/fleet.md). Credentials are named by file and read when needed, never kept in
// anything that is printed or logged.
#include <cstdint>
#include <filesystem>
#include <string>

namespace colorlab::fleet {

struct ShipConfig {
  std::filesystem::path state_dir = "./colorlab-state";  // colorlabd's: colorlab.db and blobs/
  std::string bench_id;                                  // stable, unique in the lab: the events' key
  std::string bench_name;
  std::string postgres;     // libpq conninfo; a password belongs in a passfile=, never here
  std::string s3_endpoint;  // e.g. https://s3.lab.example:443 (path-style requests)
  std::string bucket;
  std::string region = "us-east-1";
  std::filesystem::path access_key_file;
  std::filesystem::path secret_key_file;
  // An https:// s3_endpoint's CA (PEM) when the store's certificate is not signed by a CA the system trusts
  // (docs/fleet.md, "HTTPS object store"); empty: the system's CA certificates.
  std::filesystem::path s3_ca_file;
  int batch_runs = 50;  // runs shipped per cycle
  // One PostgreSQL transaction (one fsync'd commit) takes consecutive runs until it holds transaction_runs runs
  // or at least transaction_measurements measurements; a run is never split (docs/fleet.md, "Sizing").
  int transaction_runs = 100;
  std::int64_t transaction_measurements = 200000;
  double interval_s = 30;    // between cycles when running as a service
  int stall_timeout_s = 30;  // an S3 request under 1 KiB/s for this long ends the cycle (retried next cycle)
  // `colorlab backup` rotation (docs/fleet.md, "Backups"): after a successful upload the bucket keeps the
  // newest snapshot of each of the last backup_keep_daily days and of each of the last backup_keep_weekly weeks
  // (Monday to Sunday, UTC) that have one; the snapshot just taken is always kept.
  int backup_keep_daily = 7;
  int backup_keep_weekly = 4;

  std::filesystem::path database_path() const { return state_dir / "colorlab.db"; }
  std::filesystem::path blob_root() const { return state_dir / "blobs"; }
  // Where the agent records the position central holds, for colorlabd's blob retention (docs/fleet.md).
  std::filesystem::path shipped_position_file() const { return state_dir / "ship" / "shipped-position"; }
  // Where `colorlab backup` writes its snapshot before the upload (on the bench's own disk).
  std::filesystem::path backup_dir() const { return state_dir / "backup"; }
};

// Error{bad_parameter} naming the file, line and key for anything missing or malformed.
ShipConfig load_ship_config(const std::filesystem::path& toml_file);

// The first line of a credential file, without its line ending; Error{bad_parameter} when it cannot be
// read or is empty. The message names the file, never its content. When systemd passed a credential of the
// file's name ($CREDENTIALS_DIRECTORY/<file name>, the units' LoadCredential=), that copy is read instead.
std::string read_secret_file(const std::filesystem::path& file, const char* what);

// The position the agent last saw central accept for this bench (0 when it never shipped).
long long read_shipped_position(const std::filesystem::path& file);
// Durable: temporary file, fsync, rename, directory fsync.
void write_shipped_position(const std::filesystem::path& file, long long position);

}  // namespace colorlab::fleet
