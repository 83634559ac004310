#include "backup_bucket.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <set>

#include "colorlab/core/error.hpp"
#include "colorlab/fleet/backup.hpp"
#include "colorlab/store/blob_store.hpp"

namespace colorlab::fleet {

namespace fs = std::filesystem;
using nlohmann::json;

S3Client bucket_for(const ShipConfig& c) {
  S3Credentials k{read_secret_file(c.access_key_file, "S3 access key"),
                  read_secret_file(c.secret_key_file, "S3 secret key")};
  S3Client s3(c.s3_endpoint, c.bucket, c.region, std::move(k));
  s3.set_stall_timeout(c.stall_timeout_s);
  s3.set_ca_file(c.s3_ca_file);
  return s3;
}

std::string backup_prefix(const ShipConfig& c) { return "backups/" + c.bench_id + "/"; }

json read_index(S3Client& s3, const ShipConfig& c) {
  json index{{"format", 1}, {"snapshots", json::array()}, {"restores", json::array()}};
  std::string text;
  try {
    text = s3.get_part(backup_prefix(c) + "index.json", std::nullopt);
  } catch (const Error& e) {
    if (e.cls() == ErrorClass::not_found) return index;
    throw;
  }
  try {
    json stored = json::parse(text);
    if (stored.contains("snapshots")) index["snapshots"] = stored.at("snapshots");
    if (stored.contains("restores")) index["restores"] = stored.at("restores");
  } catch (const json::exception& e) {
    throw Error(ErrorClass::bad_data, "the bucket's " + backup_prefix(c) + "index.json is not a backup index: " + e.what(),
                "was it written by something else? Each snapshot's manifest.json still names its database");
  }
  return index;
}

void put_json(S3Client& s3, const fs::path& scratch, const std::string& key, const json& doc) {
  fs::create_directories(scratch);
  const fs::path tmp = scratch / "upload.json.tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << doc.dump(1) << "\n";
    out.flush();
    if (!out) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw Error(ErrorClass::io_error, "cannot write " + tmp.string(), "free space under " + scratch.string());
    }
  }
  try {
    s3.put_file(key, tmp, store::BlobStore::hash_file(tmp));
  } catch (...) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
  std::error_code ec;
  fs::remove(tmp, ec);
}

void fsync_file(const fs::path& p, bool directory) {
  int fd = ::open(p.c_str(), O_RDONLY | O_CLOEXEC | (directory ? O_DIRECTORY : 0));
  if (fd < 0) throw Error(ErrorClass::io_error, "cannot open " + p.string() + " to sync it: " + std::strerror(errno));
  const bool ok = ::fsync(fd) == 0;
  const int err = errno;
  ::close(fd);
  if (!ok) throw Error(ErrorClass::io_error, "cannot fsync " + p.string() + ": " + std::strerror(err));
}

namespace {

// Days since 1970-01-01 of a snapshot name (YYYY-MM-DDT...).
long days_of(const std::string& name) {
  using namespace std::chrono;
  int y = 0;
  unsigned m = 0, d = 0;
  if (name.size() < 10 || std::sscanf(name.c_str(), "%4d-%2u-%2u", &y, &m, &d) != 3) {
    throw Error(ErrorClass::bad_data, "'" + name + "' is no snapshot name (YYYY-MM-DDTHHMMSS.mmmZ)");
  }
  return sys_days(year{y} / month{m} / day{d}).time_since_epoch().count();
}

}  // namespace

std::vector<std::string> snapshots_to_keep(std::vector<std::string> names, int keep_daily, int keep_weekly) {
  std::sort(names.begin(), names.end(), std::greater<>());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  std::set<std::string> keep;
  if (!names.empty()) keep.insert(names.front());
  std::set<long> days, weeks;
  for (const auto& n : names) {  // newest first: the first of each day or week is its newest
    const long day = days_of(n);
    // 1970-01-01 was a Thursday: +3 makes weeks start on Monday.
    const long week = (day + 3) >= 0 ? (day + 3) / 7 : -((-(day + 3) + 6) / 7);
    if (!days.count(day) && static_cast<int>(days.size()) < keep_daily) {
      days.insert(day);
      keep.insert(n);
    }
    if (!weeks.count(week) && static_cast<int>(weeks.size()) < keep_weekly) {
      weeks.insert(week);
      keep.insert(n);
    }
  }
  return {keep.rbegin(), keep.rend()};
}

}  // namespace colorlab::fleet
