#pragma once
// One shipping cycle: the bench's ended runs after the position central holds, each as blobs first (to the
// bucket, content-addressed) and then its rows plus the new position in one PostgreSQL transaction (several
// consecutive runs share one), checked by the per-run digest before that transaction commits. A mismatch rolls the
// transaction back and its runs go again one a transaction, so the runs before the divergent one commit and it
// alone is reported. A kill at any moment leaves central at the old position
// (the next cycle re-sends; content addressing and ON CONFLICT DO NOTHING make that harmless) or the new one.
#include <cstdint>
#include <string>
#include <vector>

#include "colorlab/fleet/config.hpp"

namespace colorlab::fleet {

struct Divergence {
  std::string run_id;
  std::string bench_digest;
  std::string central_digest;
};

struct CycleReport {
  std::int64_t position_before = 0;
  std::int64_t position_after = 0;
  int runs_shipped = 0;
  std::int64_t measurements = 0;
  std::int64_t events = 0;
  int blobs_uploaded = 0;               // not already in the bucket
  std::vector<Divergence> divergences;  // shipping stopped at the first
  // Runs a restored bench ended again that central holds from before the restore (backup.hpp): central's copy
  // stays, the position moves on.
  std::vector<Divergence> superseded;
  int transactions = 0;  // committed; several runs each (config transaction_runs, transaction_measurements)
  // Where the cycle's time went, in seconds (docs/PERFORMANCE.md, "Shipping a backlog"): reading the bench's
  // SQLite with the COPY text and the bench's digest made from it (on a thread of its own, overlapping the rest;
  // read_wait is how long shipping waited for it); the blobs (HEAD and PUT); COPY; the insert-or-ignore from
  // staging; central's digest; COMMIT (the fsync).
  struct Seconds {
    double read = 0, read_wait = 0, blobs = 0, copy = 0, merge = 0, digest = 0, commit = 0;
  } seconds;
};

// Sets up an empty central database; refuses a schema of another version (central_schema.hpp).
void central_init(const ShipConfig& config);

// Ships up to config.batch_runs runs. Throws colorlab::Error for anything that stops the cycle (no connection,
// wrong credentials, a refused blob); nothing is marked shipped past the last run that committed.
CycleReport ship_cycle(const ShipConfig& config);

// Recomputes the digest of every run central holds for this bench on both sides (a row altered on the bench
// after it shipped shows here). Each mismatch is recorded in central's ship_problems.
std::vector<Divergence> verify_shipped(const ShipConfig& config);

}  // namespace colorlab::fleet
