#include <algorithm>
#include <fstream>
#include <span>

#include <nlohmann/json.hpp>

#include "backup_bucket.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/core/ids.hpp"
#include "colorlab/fleet/backup.hpp"
#include "colorlab/fleet/s3.hpp"
#include "colorlab/store/blob_store.hpp"
#include "colorlab/store/sqlite.hpp"

namespace colorlab::fleet {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

const json& pick(const json& index, const std::string& name, const ShipConfig& c) {
  const json& snaps = index["snapshots"];
  if (snaps.empty()) {
    throw Error(ErrorClass::not_found, "the bucket '" + c.bucket + "' holds no backup of bench " + c.bench_id,
                "check [ship] bench_id and bucket; `colorlab backup` makes one");
  }
  const json* best = nullptr;
  for (const auto& s : snaps) {
    const std::string n = s["name"].get<std::string>();
    if (name.empty() ? (!best || n > (*best)["name"].get<std::string>()) : n == name) best = &s;
  }
  if (!best) {
    std::string known;
    for (const auto& s : snaps) known += (known.empty() ? "" : ", ") + s["name"].get<std::string>();
    throw Error(ErrorClass::not_found, "bench " + c.bench_id + " has no snapshot named " + name,
                "snapshots kept: " + known);
  }
  return *best;
}

// One past every epoch this bench has used: its snapshots' last events and every restore so far (a bench
// restored twice from the same snapshot must not meet its own earlier epoch).
std::int64_t next_epoch(const json& index) {
  std::int64_t e = 0;
  for (const auto& s : index["snapshots"]) e = std::max(e, epoch_of(s.value("last_event", std::int64_t{0})));
  for (const auto& r : index["restores"]) e = std::max(e, r.value("epoch", std::int64_t{0}));
  return e + 1;
}

void write_file(const fs::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.flush();
  if (!out) throw Error(ErrorClass::io_error, "cannot write " + p.string(), "free space under " + p.parent_path().string());
}

}  // namespace

RestoreReport restore(const ShipConfig& c, const std::string& name, const fs::path& into) {
  const fs::path database = into / "colorlab.db";
  // A stale -wal beside the restored file would be replayed onto it when colorlabd opens it.
  for (const char* name : {"colorlab.db", "colorlab.db-wal", "colorlab.db-shm"}) {
    if (fs::exists(into / name)) {
      throw Error(ErrorClass::conflict, into.string() + " already holds a bench database (" + name + ")",
                  "restore into an empty directory (--into), or move the old state directory away first");
    }
  }
  S3Client s3 = bucket_for(c);
  json index = read_index(s3, c);
  const json entry = pick(index, name, c);
  RestoreReport report;
  report.name = entry["name"].get<std::string>();
  report.state_dir = into;
  const std::string prefix = backup_prefix(c) + report.name + "/";
  json manifest;
  try {
    manifest = json::parse(s3.get_part(prefix + "manifest.json", std::nullopt));
  } catch (const json::exception& e) {
    throw Error(ErrorClass::bad_data, prefix + "manifest.json is not a snapshot manifest: " + e.what());
  }
  report.last_event = manifest.at("last_event").get<std::int64_t>();

  // The epoch is claimed in the bucket before anything is written here: a restore that fails half-way burns
  // an epoch, which costs nothing, while two restores never share one.
  report.epoch = next_epoch(index);
  report.next_event = (report.epoch << kEpochShift) + 1;
  index["restores"].push_back({{"epoch", report.epoch}, {"from", report.name}, {"at", now_iso8601()}});
  put_json(s3, into / "restore-scratch", backup_prefix(c) + "index.json", index);
  fs::remove_all(into / "restore-scratch");

  fs::create_directories(into);
  const fs::path tmp = into / "colorlab.db.restore-tmp";
  {
    const std::string bytes = s3.get_part(manifest.at("database").at("key").get<std::string>(), std::nullopt);
    if (sha256_hex(bytes) != manifest["database"]["sha256"].get<std::string>()) {
      throw Error(ErrorClass::bad_data, "the snapshot " + report.name + " read back from the bucket does not hash to its manifest's SHA-256",
                  "try another snapshot: colorlab restore --snapshot NAME");
    }
    write_file(tmp, bytes);
  }
  std::vector<std::string> blobs;
  {
    store::Database db(tmp.string(), false);
    std::string verdict;
    auto check = db.prepare("PRAGMA integrity_check");
    while (check.step()) verdict += (verdict.empty() ? "" : "; ") + check.text(0);
    if (verdict != "ok") throw Error(ErrorClass::bad_data, "the snapshot " + report.name + " fails PRAGMA integrity_check: " + verdict);
    // AUTOINCREMENT hands out max(sqlite_sequence, max(seq)) + 1: the restored bench's events start the epoch.
    db.exec("DELETE FROM sqlite_sequence WHERE name = 'event_log'");
    db.prepare("INSERT INTO sqlite_sequence (name, seq) VALUES ('event_log', ?1)")
        .bind(1, static_cast<std::int64_t>(report.epoch << kEpochShift))
        .run();
    auto r = db.prepare("SELECT count(*) FROM runs");
    if (r.step()) report.runs = r.int64(0);
    auto b = db.prepare("SELECT sha256 FROM blobs ORDER BY sha256");
    while (b.step()) blobs.push_back(b.text(0));
  }

  // Blobs before the database takes its name: a colorlab.db in the directory means the restore completed.
  store::BlobStore files(into / "blobs");
  for (const auto& sha : blobs) {
    std::string bytes;
    try {
      bytes = s3.get_part(blob_key(sha), std::nullopt);
    } catch (const Error& e) {
      if (e.cls() != ErrorClass::not_found) throw;
      report.blobs_missing.push_back(sha);
      continue;
    }
    const auto* p = reinterpret_cast<const std::uint8_t*>(bytes.data());
    if (files.put(std::span<const std::uint8_t>(p, bytes.size())) != sha) {
      throw Error(ErrorClass::bad_data, "the bucket's object sha256/" + sha + " does not hash to its name",
                  "the bucket is damaged; restore stopped before the database was put in place");
    }
    ++report.blobs_restored;
  }
  fsync_file(tmp);
  fs::rename(tmp, database);
  fsync_file(into, true);
  return report;
}

}  // namespace colorlab::fleet
