#pragma once
// What colorlab-central reads from the central PostgreSQL, in the bench's own record types (store.hpp), so the
// API's documents and exports are built by the same code as on a bench. A small pool of connections serves the
// HTTP pool's threads: libpq connections are not shared between threads, and a lost one is dropped, not reused.
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/campaigns/run_reader.hpp"
#include "colorlab/fleet/pg.hpp"
#include "colorlab/store/blob_index.hpp"
#include "colorlab/store/store.hpp"

namespace colorlab::fleet {

class PgPool {
 public:
  PgPool(std::string conninfo, unsigned max_connections);

  // One connection for the caller's request; back to the pool when the lease ends, dropped when it was lost
  // (the next lease connects again: PostgreSQL restarted is a few 502s, not a dead server).
  class Lease {
   public:
    Lease(PgPool& pool, std::unique_ptr<Pg> pg) : pool_(&pool), pg_(std::move(pg)) {}
    Lease(Lease&& o) noexcept : pool_(o.pool_), pg_(std::move(o.pg_)), broken_(o.broken_) {}
    ~Lease();
    Pg& operator*() { return *pg_; }
    Pg* operator->() { return pg_.get(); }
    void broken() { broken_ = true; }

   private:
    PgPool* pool_;
    std::unique_ptr<Pg> pg_;
    bool broken_ = false;
  };
  Lease lease();

 private:
  void give_back(std::unique_ptr<Pg> pg, bool broken);
  std::string conninfo_;
  unsigned max_;
  std::mutex mutex_;
  std::condition_variable freed_;
  std::vector<std::unique_ptr<Pg>> idle_;
  unsigned open_ = 0;
};

struct CentralRun {
  store::RunRecord run;  // seq: the run's seq on its bench
  std::string bench_id;
  std::string bench_name;
};

// GET /v1/runs on central: the bench's filters plus which bench and when (created_at, ISO 8601).
struct CentralRunFilter {
  std::string campaign;
  std::string status;
  std::string bench;
  std::string since;  // created at or after
  std::string until;  // created before
};

struct CentralRunPage {
  std::vector<CentralRun> runs;
  std::optional<std::string> next_cursor;  // the last run's id: newest first by UUIDv7 across benches
};

struct CentralBlobRef {
  std::string name, sha256, kind, step, created_at;
  store::BlobRecord blob;
};

std::optional<CentralRun> central_run(Pg& pg, const std::string& id);
// What says a run's rows are still the ones an answer was built from (its `runs` row version), or nothing when
// central holds no such run; and the same for the whole run listing (every bench's row version). AnswerCache.
std::optional<std::string> central_run_validator(Pg& pg, const std::string& id);
std::string central_catalog_validator(Pg& pg);
// Error{bad_parameter} for a cursor that is no run id, or a since/until PostgreSQL cannot read as a time.
CentralRunPage central_runs(Pg& pg, unsigned limit, const std::optional<std::string>& cursor,
                            const CentralRunFilter& filter);
std::int64_t central_measurement_count(Pg& pg, const std::string& run_id);
// As Store::measurements_page: seq order after `after_seq`, the same filters.
store::MeasurementPage central_measurements_page(Pg& pg, const std::string& run_id,
                                                 const store::MeasurementFilter& filter, std::int64_t after_seq,
                                                 unsigned limit);
std::vector<CentralBlobRef> central_run_blobs(Pg& pg, const std::string& run_id);
std::optional<store::BlobRecord> central_blob(Pg& pg, const std::string& sha256);
// GET /v1/benches: every bench with its shipped position, last error and lag.
nlohmann::json central_benches(Pg& pg);

// campaigns::RunReader over central (a camera run's .ti3 pairs it with the chart-read run it names).
class CentralRunReader final : public campaigns::RunReader {
 public:
  explicit CentralRunReader(Pg& pg) : pg_(pg) {}
  std::optional<campaigns::StoredRun> run(const std::string& run_id) override;

 private:
  Pg& pg_;
};

}  // namespace colorlab::fleet
