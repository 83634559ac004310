#pragma once
// The bench's side of shipping: colorlabd's SQLite opened read-only (query_only, a WAL reader never waits for
// the daemon's writer and the daemon never waits for it), read in one read transaction per run so a run's rows,
// its events and its digest come from one snapshot. It never writes the bench's database.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "colorlab/store/ship_log.hpp"
#include "colorlab/store/sqlite.hpp"

namespace colorlab::fleet {

// A run that ended (finished_ok, finished_error, aborted, interrupted) at event `ended_event`.
struct EndedRun {
  std::int64_t ended_event = 0;
  std::string run_id;
  std::string status;
};

// What the bench holds ended but not yet shipped after a position: central shows it as the bench's lag.
// Ended runs not yet shipped after a position, as the bench itself counts them (store::ShipLog).
using Backlog = store::ShipBacklog;

struct BlobToShip {
  std::string sha256;
  std::uint64_t size = 0;
};

// A run's rows as COPY text (columns as in shipper.cpp's staging tables), ready for central.
struct RunBatch {
  EndedRun run;
  std::string runs, executions, measurements, blobs, run_blobs, events;
  std::int64_t measurement_count = 0;
  std::int64_t event_count = 0;
  std::vector<BlobToShip> blob_files;
  std::string digest;
};

class BenchReader {
 public:
  // Error{io_error} when the database cannot be opened (colorlabd never ran with this state_dir?).
  explicit BenchReader(const std::filesystem::path& database);

  int schema_version();
  // The newest event's seq (0 for none); its epoch is the bench's (backup.hpp).
  std::int64_t last_event();
  // Runs that ended after `position`, oldest first, at most `limit`.
  std::vector<EndedRun> ended_after(std::int64_t position, int limit);
  Backlog backlog(std::int64_t position);
  // The run's rows and the bench's events (position, run.ended_event], from one snapshot.
  RunBatch read(const std::string& bench_id, const EndedRun& run, std::int64_t position);
  // The digest of the run as the bench holds it now (for `colorlab-ship verify`).
  std::string digest(const std::string& run_id);

 private:
  std::string digest_locked(const std::string& run_id);
  store::Database db_;
};

}  // namespace colorlab::fleet
