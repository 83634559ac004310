#pragma once
// The rows that reference the blob store's files (tables `blobs` and `run_blobs`, schema 5), on a
// Store's connection: the writer's for changes, a reader's for the API. The files themselves are
// blob_store.hpp's.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/store/sqlite.hpp"
#include "colorlab/store/step_blob.hpp"
#include "colorlab/store/store.hpp"

namespace colorlab::store {

struct BlobRecord {
  std::string sha256;
  std::uint64_t size = 0;
  std::string media_type;
  nlohmann::json meta = nlohmann::json::object();
  std::string created_at;
};

struct RunBlobRecord {
  std::string run_id;
  std::string name;
  std::string step;
  std::string kind;
  std::string created_at;
  BlobRecord blob;
};

// One blob retention would remove: its row, the runs' references to it and its file.
struct ExpiredBlob {
  std::string sha256;
  std::uint64_t size = 0;
  std::vector<std::string> references;  // "run_id/name"
};

class BlobIndex {
 public:
  explicit BlobIndex(Store& store) : store_(store), db_(store.db_) {}

  std::optional<BlobRecord> blob(const std::string& sha256);
  // Every row, for the start-up check.
  std::vector<BlobRecord> all();
  // A run's blobs in the order they were kept.
  std::vector<RunBlobRecord> of_run(const std::string& run_id);
  // A PNG preview already kept for a blob (meta.preview_of), if any.
  std::optional<std::string> preview_of(const std::string& sha256);

  // Blobs whose every reference was created before `cutoff` (ISO 8601) and is of a kind not in
  // `keep`, plus unreferenced rows older than the cutoff. With `shipped_upto` (colorlab-ship's position in the
  // event log), only blobs whose every referencing run ended at or before that event: nothing unshipped goes.
  std::vector<ExpiredBlob> expired(const std::string& cutoff, const std::vector<std::string>& keep,
                                   std::optional<std::int64_t> shipped_upto = std::nullopt);
  // Removes the rows of these blobs and every reference to them, in one transaction, with an event.
  void remove(const std::vector<ExpiredBlob>& blobs, const nlohmann::json& event);

 private:
  Store& store_;
  Database& db_;
};

// Inside commit_step's transaction: the blob rows (once per content) and the run's references.
void insert_step_blobs(Database& db, const std::string& run_id, const std::string& step,
                       const std::vector<StepBlob>& blobs, const std::string& now);

}  // namespace colorlab::store
