#pragma once
// Backups of one bench into the lab's bucket (docs/fleet.md, "Backups"). A snapshot is the bench's SQLite store
// copied by VACUUM INTO while colorlabd writes (one read transaction: a consistent moment), checked with
// PRAGMA integrity_check, fsynced and renamed into place before anything is uploaded. The blobs it references go
// to the same content-addressed keys the shipper uses (sha256/<hex>), so a blob is stored once for both.
//
// In the bucket, under backups/<bench_id>/:
//   <name>/colorlab.db      the snapshot (name: its UTC time, e.g. 2026-11-29T054400.123Z)
//   <name>/manifest.json    what it holds: size and SHA-256, the last event, runs, blobs, the epoch
//   index.json              the snapshots kept and every restore (written last: it never names a missing object)
//
// Restore epochs: event_log seqs are the shipped position central holds. A bench restored from an older
// snapshot would hand out seqs central already has (for other events), so each restore starts a new epoch:
// the restored database's next event is epoch << kEpochShift, one past anything the bench, its snapshots or
// an earlier restore ever used. The shipper treats a run central got in an earlier epoch as central's
// (shipper.hpp), so a run the dead bench finished after the snapshot does not stop shipping.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "colorlab/fleet/config.hpp"

namespace colorlab::fleet {

// 2^40 events per epoch: a bench writing 1,000 events a second needs 35 years to fill one.
inline constexpr int kEpochShift = 40;
inline constexpr std::int64_t epoch_of(std::int64_t event_seq) { return event_seq >> kEpochShift; }

struct BackupReport {
  std::string name;
  std::string database_key;
  std::uint64_t database_bytes = 0;
  std::int64_t last_event = 0;
  std::int64_t runs = 0;
  std::int64_t blobs = 0;                  // referenced by the snapshot
  std::int64_t blobs_uploaded = 0;         // not in the bucket before
  std::vector<std::string> blobs_missing;  // neither on the bench's disk nor in the bucket: lost before this backup
  std::vector<std::string> rotated_out;    // snapshots removed by the rotation policy
};

// Snapshot, upload, manifest, index, rotation. Error{io_error} when the snapshot cannot be written or fails its
// integrity check (nothing of it is left on disk or in the bucket), Error{no_comms}/io_error from the bucket.
BackupReport backup(const ShipConfig& config);

struct RestoreReport {
  std::string name;  // the snapshot restored
  std::filesystem::path state_dir;
  std::int64_t epoch = 0;
  std::int64_t next_event = 0;  // the restored bench's first new event seq
  std::int64_t last_event = 0;  // the snapshot's last event
  std::int64_t runs = 0;
  std::int64_t blobs_restored = 0;
  std::vector<std::string> blobs_missing;  // named by the snapshot, absent from the bucket
};

// Rebuilds `into` (a directory without a colorlab.db) from the named snapshot, or the newest when `name` is
// empty: database, blobs and a new epoch. Error{conflict} when `into` already holds a database.
RestoreReport restore(const ShipConfig& config, const std::string& name, const std::filesystem::path& into);

// The rotation policy on snapshot names (their UTC times, any order): the ones to keep. The newest is always
// kept; then the newest of each of the last `keep_daily` days and of the last `keep_weekly` weeks (from Monday,
// UTC) that hold a snapshot.
std::vector<std::string> snapshots_to_keep(std::vector<std::string> names, int keep_daily, int keep_weekly);

}  // namespace colorlab::fleet
