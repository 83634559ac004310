#include "colorlab/store/blob_index.hpp"

#include <map>

#include "colorlab/core/error.hpp"
#include "colorlab/store/ship_log.hpp"

namespace colorlab::store {

namespace {

nlohmann::json meta_of(const std::string& text) {
  auto j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  return j.is_object() ? j : nlohmann::json::object();
}

BlobRecord read_blob(Statement& st, int col) {
  return BlobRecord{st.text(col), static_cast<std::uint64_t>(st.int64(col + 1)), st.text(col + 2),
                    meta_of(st.text(col + 3)), st.text(col + 4)};
}

constexpr const char* kBlobColumns = "b.sha256, b.size, b.media_type, b.meta, b.created_at";

}  // namespace

std::optional<BlobRecord> BlobIndex::blob(const std::string& sha256) {
  auto st = db_.prepare(std::string("SELECT ") + kBlobColumns + " FROM blobs b WHERE b.sha256 = ?1");
  st.bind(1, std::string_view(sha256));
  if (!st.step()) return std::nullopt;
  return read_blob(st, 0);
}

std::vector<BlobRecord> BlobIndex::all() {
  auto st = db_.prepare(std::string("SELECT ") + kBlobColumns + " FROM blobs b ORDER BY b.sha256");
  std::vector<BlobRecord> out;
  while (st.step()) out.push_back(read_blob(st, 0));
  return out;
}

std::vector<RunBlobRecord> BlobIndex::of_run(const std::string& run_id) {
  // run_blobs has no rowid: the order they were kept is their creation time, then their name.
  auto st = db_.prepare(std::string("SELECT r.run_id, r.name, r.step, r.kind, r.created_at, ") + kBlobColumns +
                        " FROM run_blobs r JOIN blobs b ON b.sha256 = r.sha256 WHERE r.run_id = ?1 "
                        "ORDER BY r.created_at, r.name");
  st.bind(1, std::string_view(run_id));
  std::vector<RunBlobRecord> out;
  while (st.step()) {
    out.push_back(RunBlobRecord{st.text(0), st.text(1), st.text(2), st.text(3), st.text(4), read_blob(st, 5)});
  }
  return out;
}

std::optional<std::string> BlobIndex::preview_of(const std::string& sha256) {
  auto st = db_.prepare(
      "SELECT sha256 FROM blobs WHERE media_type = 'image/png' AND json_extract(meta, '$.preview_of') = ?1 LIMIT 1");
  st.bind(1, std::string_view(sha256));
  if (!st.step()) return std::nullopt;
  return st.text(0);
}

std::vector<ExpiredBlob> BlobIndex::expired(const std::string& cutoff, const std::vector<std::string>& keep,
                                            std::optional<std::int64_t> shipped_upto) {
  const std::string kinds = nlohmann::json(keep).dump();
  // ?3 < 0: no shipping. Otherwise a run counts as shipped when the event that ended it is at or before ?3, the
  // same test colorlab-ship uses to pick what to ship (fleet/src/bench_reader.cpp).
  auto st = db_.prepare(
      "SELECT b.sha256, b.size, r.run_id, r.name FROM blobs b LEFT JOIN run_blobs r ON r.sha256 = b.sha256 "
      "WHERE b.created_at < ?1 AND NOT EXISTS (SELECT 1 FROM run_blobs k WHERE k.sha256 = b.sha256 AND "
      "(k.created_at >= ?1 OR k.kind IN (SELECT value FROM json_each(?2)))) "
      "AND (?3 < 0 OR NOT EXISTS (SELECT 1 FROM run_blobs u WHERE u.sha256 = b.sha256 AND NOT EXISTS ("
      "SELECT 1 FROM event_log e WHERE e.seq <= ?3 AND e.topic = 'execution' AND "
      "json_extract(e.payload, '$.run_id') = u.run_id AND "
      "json_extract(e.payload, '$.status') IN " +
      std::string(kEndedStatusesSql) + "))) "
                                       "ORDER BY b.sha256");
  st.bind(1, std::string_view(cutoff)).bind(2, std::string_view(kinds)).bind(3, shipped_upto.value_or(-1));
  std::vector<ExpiredBlob> out;
  while (st.step()) {
    if (out.empty() || out.back().sha256 != st.text(0)) {
      out.push_back(ExpiredBlob{st.text(0), static_cast<std::uint64_t>(st.int64(1)), {}});
    }
    if (!st.is_null(2)) out.back().references.push_back(st.text(2) + "/" + st.text(3));
  }
  return out;
}

void BlobIndex::remove(const std::vector<ExpiredBlob>& blobs, const nlohmann::json& event) {
  Transaction tx(db_);
  auto refs = db_.prepare("DELETE FROM run_blobs WHERE sha256 = ?1");
  auto rows = db_.prepare("DELETE FROM blobs WHERE sha256 = ?1");
  for (const auto& b : blobs) {
    refs.bind(1, std::string_view(b.sha256));
    refs.run();
    refs.reset();
    rows.bind(1, std::string_view(b.sha256));
    rows.run();
    rows.reset();
  }
  store_.append_event("blobs", event);
  tx.commit();
}

void insert_step_blobs(Database& db, const std::string& run_id, const std::string& step,
                       const std::vector<StepBlob>& blobs, const std::string& now) {
  if (blobs.empty()) return;
  // Content already stored (the same preview, identical frames) keeps its first row.
  auto blob = db.prepare(
      "INSERT INTO blobs (sha256, size, media_type, meta, created_at) VALUES (?1, ?2, ?3, ?4, ?5) "
      "ON CONFLICT (sha256) DO NOTHING");
  auto ref = db.prepare("INSERT INTO run_blobs (run_id, name, sha256, step, kind, created_at) VALUES (?1, ?2, ?3, ?4, ?5, ?6)");
  for (const auto& b : blobs) {
    if (b.sha256.size() != 64 || b.name.empty() || b.kind.empty() || b.media_type.empty()) {
      throw Error(ErrorClass::internal, "a kept blob without sha256, name, kind or media type: " + b.name);
    }
    blob.bind(1, std::string_view(b.sha256))
        .bind(2, static_cast<std::int64_t>(b.size))
        .bind(3, std::string_view(b.media_type))
        .bind(4, std::string_view(b.meta.is_object() ? b.meta.dump() : std::string("{}")))
        .bind(5, std::string_view(now));
    blob.run();
    blob.reset();
    ref.bind(1, std::string_view(run_id))
        .bind(2, std::string_view(b.name))
        .bind(3, std::string_view(b.sha256))
        .bind(4, std::string_view(step))
        .bind(5, std::string_view(b.kind))
        .bind(6, std::string_view(now));
    ref.run();
    ref.reset();
  }
}

}  // namespace colorlab::store
