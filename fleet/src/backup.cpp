#include "colorlab/fleet/backup.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <set>

#include <nlohmann/json.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/core/ids.hpp"
#include "colorlab/core/log.hpp"
#include "colorlab/fleet/s3.hpp"
#include "colorlab/store/blob_store.hpp"
#include "colorlab/store/sqlite.hpp"
#include "backup_bucket.hpp"

namespace colorlab::fleet {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Its UTC time without ':' (a key stays plain in every store's URL and signature); names sort by time.
std::string snapshot_name() {
  std::string t = now_iso8601();
  t.erase(std::remove(t.begin(), t.end(), ':'), t.end());
  return t;
}

// A snapshot left by a backup that died (a temporary file, or a finished one whose upload failed): the next
// backup starts clean rather than letting them pile up on the bench's disk.
void clear_leftovers(const fs::path& dir) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) fs::remove(e.path(), ec);
}

// One backup at a time on a bench: the timer's and a person's would clear each other's temporary snapshot in the
// middle of VACUUM INTO, and their read-modify-write of the bucket's index would drop one snapshot's entry.
class BackupLock {
 public:
  // Beside backup/, not in it: backup/ holds a snapshot or nothing.
  explicit BackupLock(const fs::path& path) {
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
    if (fd_ < 0)
      throw Error(ErrorClass::io_error, "cannot open " + path.string(), "free space (or fix the disk) under " + path.parent_path().string());
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      ::close(fd_);
      throw Error(ErrorClass::conflict, "another colorlab backup is running on this bench (" + path.string() + " is locked)",
                  "wait for it to finish; its snapshot is as good as this one would be");
    }
  }
  ~BackupLock() { ::close(fd_); }  // closing releases the lock, also when the process dies
  BackupLock(const BackupLock&) = delete;
  BackupLock& operator=(const BackupLock&) = delete;

 private:
  int fd_ = -1;
};

struct Snapshot {
  fs::path file;
  std::int64_t last_event = 0;
  std::int64_t runs = 0;
  int schema = 0;
  std::vector<std::string> blobs;
};

// VACUUM INTO reads in one transaction, so the copy is one moment of the store however fast colorlabd commits;
// the daemon's writer never waits for it (WAL). The copy is checked and made durable before it gets its name.
Snapshot take_snapshot(const fs::path& database, const fs::path& dir, const std::string& name) {
  const fs::path tmp = dir / (name + ".db.tmp");
  const fs::path final_path = dir / (name + ".db");
  const std::string hint = "free space (or fix the disk) under " + dir.string() + "; nothing of this snapshot was kept";
  Snapshot s;
  try {
    {
      store::Database src(database.string(), true);
      src.exec("PRAGMA busy_timeout = 5000");
      src.prepare("VACUUM INTO ?1").bind(1, std::string_view(tmp.string())).run();
    }
    store::Database snap(tmp.string(), true);
    std::string verdict;
    auto check = snap.prepare("PRAGMA integrity_check");
    while (check.step()) verdict += (verdict.empty() ? "" : "; ") + check.text(0);
    if (verdict != "ok") {
      throw Error(ErrorClass::bad_data, "the snapshot fails PRAGMA integrity_check: " + verdict,
                  "the bench's own database may be damaged: stop colorlabd and run PRAGMA integrity_check on it");
    }
    auto v = snap.prepare("PRAGMA user_version");
    if (v.step()) s.schema = static_cast<int>(v.int64(0));
    auto e = snap.prepare("SELECT coalesce(max(seq), 0) FROM event_log");
    if (e.step()) s.last_event = e.int64(0);
    auto r = snap.prepare("SELECT count(*) FROM runs");
    if (r.step()) s.runs = r.int64(0);
    auto b = snap.prepare("SELECT sha256 FROM blobs ORDER BY sha256");
    while (b.step()) s.blobs.push_back(b.text(0));
  } catch (const Error& e) {
    std::error_code ec;
    fs::remove(tmp, ec);
    if (e.cls() == ErrorClass::bad_data) throw;
    throw Error(ErrorClass::io_error, "cannot write the snapshot " + tmp.string() + ": " + e.what(), hint);
  }
  try {
    fsync_file(tmp);
  } catch (const Error& e) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw Error(ErrorClass::io_error, std::string(e.what()), hint);
  }
  fs::rename(tmp, final_path);
  fsync_file(dir, true);
  s.file = final_path;
  return s;
}

}  // namespace

BackupReport backup(const ShipConfig& c) {
  if (!fs::exists(c.database_path())) {
    throw Error(ErrorClass::io_error, "no bench database at " + c.database_path().string(),
                "point state_dir in the TOML at colorlabd's state directory");
  }
  try {
    fs::create_directories(c.backup_dir());
  } catch (const fs::filesystem_error& e) {
    throw Error(ErrorClass::io_error, "cannot write the snapshot directory " + c.backup_dir().string() + ": " + e.code().message(),
                "free space (or fix the disk) under " + c.backup_dir().string() + "; nothing of this snapshot was kept");
  }
  const BackupLock lock(c.backup_dir().parent_path() / "backup.lock");
  clear_leftovers(c.backup_dir());
  BackupReport report;
  report.name = snapshot_name();
  const Snapshot snap = take_snapshot(c.database_path(), c.backup_dir(), report.name);
  report.last_event = snap.last_event;
  report.runs = snap.runs;
  report.blobs = static_cast<std::int64_t>(snap.blobs.size());

  S3Client s3 = bucket_for(c);
  // Blobs first: a snapshot in the bucket never names a blob the bucket lacks (unless the bench lost it).
  store::BlobStore files(c.blob_root());
  for (const auto& sha : snap.blobs) {
    const std::string key = blob_key(sha);
    if (s3.exists(key)) continue;
    const fs::path path = files.path_of(sha);
    if (!fs::exists(path)) {
      report.blobs_missing.push_back(sha);
      continue;
    }
    s3.put_file(key, path, sha);
    ++report.blobs_uploaded;
  }
  for (const auto& sha : report.blobs_missing) {
    log::warning("backup", "blob " + sha + " is referenced but neither on this bench nor in the bucket");
  }

  const std::string prefix = backup_prefix(c) + report.name + "/";
  report.database_key = prefix + "colorlab.db";
  report.database_bytes = fs::file_size(snap.file);
  const std::string sha = store::BlobStore::hash_file(snap.file);
  s3.put_file(report.database_key, snap.file, sha);
  json manifest{{"format", 1},
                {"bench_id", c.bench_id},
                {"name", report.name},
                {"created_at", now_iso8601()},
                {"database", {{"key", report.database_key}, {"sha256", sha}, {"size", report.database_bytes}}},
                {"schema_version", snap.schema},
                {"last_event", snap.last_event},
                {"epoch", epoch_of(snap.last_event)},
                {"runs", snap.runs},
                {"blobs", report.blobs},
                {"blobs_missing", report.blobs_missing}};
  put_json(s3, c.backup_dir(), prefix + "manifest.json", manifest);

  // The index last: it names only snapshots whose objects are all in the bucket. Rotation rewrites it before
  // deleting, so an interrupted rotation leaves unnamed objects, never a name without its objects.
  json index = read_index(s3, c);
  index["snapshots"].push_back({{"name", report.name}, {"last_event", snap.last_event}, {"bytes", report.database_bytes}});
  std::vector<std::string> names;
  for (const auto& e : index["snapshots"]) names.push_back(e["name"].get<std::string>());
  const auto keep = snapshots_to_keep(names, c.backup_keep_daily, c.backup_keep_weekly);
  const std::set<std::string> kept(keep.begin(), keep.end());
  json still = json::array();
  for (const auto& e : index["snapshots"]) {
    if (kept.count(e["name"].get<std::string>())) still.push_back(e);
    else report.rotated_out.push_back(e["name"].get<std::string>());
  }
  index["snapshots"] = still;
  put_json(s3, c.backup_dir(), backup_prefix(c) + "index.json", index);
  for (const auto& old : report.rotated_out) {
    try {
      s3.remove(backup_prefix(c) + old + "/colorlab.db");
      s3.remove(backup_prefix(c) + old + "/manifest.json");
    } catch (const Error& e) {
      log::warning("backup", "rotation could not delete snapshot " + old + " (the index no longer names it): " + e.what());
    }
  }
  std::error_code ec;
  fs::remove(snap.file, ec);  // the bucket holds it now; the bench's disk is for measuring
  return report;
}

}  // namespace colorlab::fleet
