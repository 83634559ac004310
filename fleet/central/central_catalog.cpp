#include "colorlab/fleet/central_catalog.hpp"

#include "colorlab/core/error.hpp"

namespace colorlab::fleet {

namespace {

nlohmann::json json_column(const PgResult& r, int row, int col) {
  if (r.is_null(row, col)) return nullptr;
  const std::string text = r.text(row, col);
  if (text.empty()) return nullptr;
  return nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
}

std::optional<std::string> opt(const std::string& s) { return s.empty() ? std::nullopt : std::optional(s); }

constexpr const char* kRunColumns =
    "r.bench_seq, r.id, r.campaign, r.params, r.status, r.simulated, r.instruments, r.created_at, r.started_at, "
    "r.finished_at, r.summary, r.error, r.script_sha256, r.bench_id, b.name";

CentralRun read_run(const PgResult& r, int i) {
  CentralRun c;
  store::RunRecord& run = c.run;
  run.seq = r.int64(i, 0);
  run.id = r.text(i, 1);
  run.campaign = r.text(i, 2);
  run.params = json_column(r, i, 3);
  run.status = r.text(i, 4);
  run.simulated = r.int64(i, 5) != 0;
  run.instruments = json_column(r, i, 6);
  run.created_at = r.text(i, 7);
  if (!r.is_null(i, 8)) run.started_at = r.text(i, 8);
  if (!r.is_null(i, 9)) run.finished_at = r.text(i, 9);
  run.summary = json_column(r, i, 10);
  run.error = json_column(r, i, 11);
  if (!r.is_null(i, 12)) run.script_sha256 = r.text(i, 12);
  c.bench_id = r.text(i, 13);
  c.bench_name = r.text(i, 14);
  return c;
}

constexpr const char* kMeasurementColumns = "seq, step, instrument_id, simulated, quantity, value, unit, data, measured_at";

store::MeasurementRecord read_measurement(const PgResult& r, int i) {
  store::MeasurementRecord m;
  m.seq = r.int64(i, 0);
  m.step = r.text(i, 1);
  m.instrument_id = r.text(i, 2);
  m.simulated = r.int64(i, 3) != 0;
  m.quantity = r.text(i, 4);
  // float8out gives the shortest text that reads back as the same double (extra_float_digits >= 1, PG 12+).
  if (!r.is_null(i, 5)) m.value = std::stod(r.text(i, 5));
  if (!r.is_null(i, 6)) m.unit = r.text(i, 6);
  m.data = json_column(r, i, 7);
  m.measured_at = r.text(i, 8);
  return m;
}

bool is_run_id(const std::string& s) {
  if (s.empty() || s.size() > 64) return false;
  for (char ch : s) {
    if (!(std::isxdigit(static_cast<unsigned char>(ch)) || ch == '-')) return false;
  }
  return true;
}

}  // namespace

PgPool::PgPool(std::string conninfo, unsigned max_connections) : conninfo_(std::move(conninfo)), max_(max_connections) {}

PgPool::Lease::~Lease() {
  if (!pg_) return;
  const bool drop = broken_ || !pg_->ok();
  pool_->give_back(std::move(pg_), drop);
}

PgPool::Lease PgPool::lease() {
  std::unique_lock lock(mutex_);
  freed_.wait(lock, [this] { return !idle_.empty() || open_ < max_; });
  if (!idle_.empty()) {
    auto pg = std::move(idle_.back());
    idle_.pop_back();
    return Lease(*this, std::move(pg));
  }
  ++open_;
  lock.unlock();
  try {
    return Lease(*this, std::make_unique<Pg>(conninfo_));
  } catch (...) {
    lock.lock();
    --open_;
    freed_.notify_one();
    throw;
  }
}

void PgPool::give_back(std::unique_ptr<Pg> pg, bool broken) {
  // Every statement here is a single PQexecParams outside any transaction, so a refused one (a 404, a bad
  // parameter) leaves the connection clean; only a lost one is dropped. It closes outside the lock.
  std::unique_ptr<Pg> drop;
  {
    std::lock_guard lock(mutex_);
    if (broken) {
      drop = std::move(pg);
      --open_;
    } else {
      idle_.push_back(std::move(pg));
    }
  }
  freed_.notify_one();
}

std::optional<CentralRun> central_run(Pg& pg, const std::string& id) {
  auto r = pg.query(std::string("SELECT ") + kRunColumns + " FROM runs r JOIN benches b ON b.id = r.bench_id WHERE r.id = $1",
                    {id});
  if (r.rows() == 0) return std::nullopt;
  return read_run(r, 0);
}

std::optional<std::string> central_run_validator(Pg& pg, const std::string& id) {
  auto r = pg.query("SELECT xmin::text FROM runs WHERE id = $1", {id});
  if (r.rows() == 0) return std::nullopt;
  return r.text(0, 0);
}

std::string central_catalog_validator(Pg& pg) {
  // Every transaction that adds runs also moves its bench's shipped_position, and a renamed bench is an update of
  // its row, so the set of (bench, row version) changes whenever the listing could. A bench row is small and
  // there are tens of them, not millions.
  return pg.query("SELECT coalesce(string_agg(id || ' ' || xmin::text, ',' ORDER BY id COLLATE \"C\"), '') FROM benches")
      .text(0, 0);
}

CentralRunPage central_runs(Pg& pg, unsigned limit, const std::optional<std::string>& cursor,
                            const CentralRunFilter& f) {
  if (cursor && !is_run_id(*cursor)) {
    throw Error(ErrorClass::bad_parameter, "cursor must be the next_cursor of the previous page");
  }
  auto check_time = [&pg](const std::string& name, const std::string& value) {
    if (value.empty()) return;
    try {
      pg.query("SELECT $1::timestamptz", {value});
    } catch (const Error& e) {
      if (e.cls() == ErrorClass::no_comms) throw;
      throw Error(ErrorClass::bad_parameter, name + " must be a time in ISO 8601, e.g. 2026-11-28T22:00:00Z",
                  "runs are filtered by when they were created");
    }
  };
  check_time("since", f.since);
  check_time("until", f.until);
  // Keyset paging on the UUIDv7 ids: newest first across benches, a page's cost independent of its depth; each
  // filter has an index on (column, id) to walk.
  auto r = pg.query(std::string("SELECT ") + kRunColumns +
                        " FROM runs r JOIN benches b ON b.id = r.bench_id"
                        " WHERE ($1::text IS NULL OR r.id < $1) AND ($2::text IS NULL OR r.campaign = $2)"
                        " AND ($3::text IS NULL OR r.status = $3) AND ($4::text IS NULL OR r.bench_id = $4)"
                        " AND ($5::timestamptz IS NULL OR r.created_at::timestamptz >= $5::timestamptz)"
                        " AND ($6::timestamptz IS NULL OR r.created_at::timestamptz < $6::timestamptz)"
                        " ORDER BY r.id DESC LIMIT $7",
                    {cursor, opt(f.campaign), opt(f.status), opt(f.bench), opt(f.since), opt(f.until),
                     std::to_string(limit + 1)});
  CentralRunPage page;
  for (int i = 0; i < r.rows(); ++i) page.runs.push_back(read_run(r, i));
  if (page.runs.size() > limit) {
    page.runs.pop_back();
    page.next_cursor = page.runs.back().run.id;
  }
  return page;
}

std::int64_t central_measurement_count(Pg& pg, const std::string& run_id) {
  return pg.query("SELECT count(*) FROM measurements WHERE run_id = $1", {run_id}).int64(0, 0);
}

store::MeasurementPage central_measurements_page(Pg& pg, const std::string& run_id,
                                                 const store::MeasurementFilter& f, std::int64_t after_seq,
                                                 unsigned limit) {
  auto r = pg.query(std::string("SELECT ") + kMeasurementColumns +
                        " FROM measurements WHERE run_id = $1 AND seq > $2"
                        " AND ($3::text IS NULL OR starts_with(step, $3)) AND ($4::text IS NULL OR quantity = $4)"
                        " AND ($5::text IS NULL OR instrument_id = $5) ORDER BY seq LIMIT $6",
                    {run_id, std::to_string(after_seq), opt(f.step_prefix), opt(f.quantity), opt(f.instrument_id),
                     std::to_string(limit + 1)});
  store::MeasurementPage page;
  for (int i = 0; i < r.rows(); ++i) page.items.push_back(read_measurement(r, i));
  if (page.items.size() > limit) {
    page.items.pop_back();
    page.next_after = page.items.back().seq;
  }
  return page;
}

std::vector<CentralBlobRef> central_run_blobs(Pg& pg, const std::string& run_id) {
  // Bytewise name order (COLLATE "C"), as SQLite orders the bench's list.
  auto r = pg.query(
      "SELECT rb.name, rb.sha256, rb.kind, rb.step, rb.created_at, b.size, b.media_type, b.meta FROM run_blobs rb "
      "JOIN blobs b ON b.sha256 = rb.sha256 WHERE rb.run_id = $1 ORDER BY rb.name COLLATE \"C\"",
      {run_id});
  std::vector<CentralBlobRef> out;
  for (int i = 0; i < r.rows(); ++i) {
    CentralBlobRef ref{r.text(i, 0), r.text(i, 1), r.text(i, 2), r.text(i, 3), r.text(i, 4), {}};
    ref.blob.sha256 = ref.sha256;
    ref.blob.size = static_cast<std::uint64_t>(r.int64(i, 5));
    ref.blob.media_type = r.text(i, 6);
    ref.blob.meta = json_column(r, i, 7);
    if (ref.blob.meta.is_null()) ref.blob.meta = nlohmann::json::object();
    out.push_back(std::move(ref));
  }
  return out;
}

std::optional<store::BlobRecord> central_blob(Pg& pg, const std::string& sha256) {
  auto r = pg.query("SELECT size, media_type, meta FROM blobs WHERE sha256 = $1", {sha256});
  if (r.rows() == 0) return std::nullopt;
  store::BlobRecord b;
  b.sha256 = sha256;
  b.size = static_cast<std::uint64_t>(r.int64(0, 0));
  b.media_type = r.text(0, 1);
  b.meta = json_column(r, 0, 2);
  if (b.meta.is_null()) b.meta = nlohmann::json::object();
  return b;
}

nlohmann::json central_benches(Pg& pg) {
  auto r = pg.query(
      "SELECT id, name, software_version, bench_schema, to_json(first_seen)#>>'{}', to_json(last_seen)#>>'{}', "
      "shipped_position, last_error, (SELECT count(*) FROM runs WHERE bench_id = benches.id), backlog_runs, "
      "oldest_unshipped_run, to_json(oldest_unshipped_ended)#>>'{}', to_json(backlog_at)#>>'{}', "
      "extract(epoch FROM now() - oldest_unshipped_ended), extract(epoch FROM now() - backlog_at) "
      "FROM benches ORDER BY id COLLATE \"C\"");
  auto text_or_null = [&r](int i, int c) { return r.is_null(i, c) ? nlohmann::json(nullptr) : nlohmann::json(r.text(i, c)); };
  auto number_or_null = [&r](int i, int c) {
    return r.is_null(i, c) ? nlohmann::json(nullptr) : nlohmann::json(std::stod(r.text(i, c)));
  };
  nlohmann::json items = nlohmann::json::array();
  for (int i = 0; i < r.rows(); ++i) {
    nlohmann::json lag{{"unshipped_runs", r.is_null(i, 9) ? nlohmann::json(nullptr) : nlohmann::json(r.int64(i, 9))},
                       {"oldest_unshipped_run", text_or_null(i, 10)},
                       {"oldest_unshipped_ended_at", text_or_null(i, 11)},
                       // Nothing unshipped when last counted: no age, however long ago that count was (see reported_at).
                       {"age_s", r.is_null(i, 10) ? nlohmann::json(r.is_null(i, 9) ? nullptr : nlohmann::json(0.0))
                                                  : number_or_null(i, 13)},
                       {"reported_at", text_or_null(i, 12)},
                       {"reported_s_ago", number_or_null(i, 14)}};
    items.push_back({{"id", r.text(i, 0)},
                     {"name", r.text(i, 1)},
                     {"software_version", r.text(i, 2)},
                     {"bench_schema", r.int64(i, 3)},
                     {"first_seen", r.text(i, 4)},
                     {"last_seen", r.text(i, 5)},
                     {"shipped_position", r.int64(i, 6)},
                     {"last_error", text_or_null(i, 7)},
                     {"runs", r.int64(i, 8)},
                     {"lag", lag}});
  }
  return {{"items", items}};
}

std::optional<campaigns::StoredRun> CentralRunReader::run(const std::string& run_id) {
  auto c = central_run(pg_, run_id);
  if (!c) return std::nullopt;
  campaigns::StoredRun out;
  out.id = c->run.id;
  out.campaign = c->run.campaign;
  out.status = c->run.status;
  out.simulated = c->run.simulated;
  out.params = c->run.params;
  std::int64_t after = 0;
  for (;;) {
    auto page = central_measurements_page(pg_, run_id, {}, after, 5000);
    for (auto& m : page.items) {
      out.measurements.push_back({m.step, m.instrument_id, m.quantity, m.value, m.unit, std::move(m.data)});
    }
    if (!page.next_after) break;
    after = *page.next_after;
  }
  return out;
}

}  // namespace colorlab::fleet
