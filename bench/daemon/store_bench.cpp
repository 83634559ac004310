// What durability costs and what keyset paging saves, measured side by side:
// - one campaign step committed by the store against the same rows through raw SQLite with the store's own
//   schema and settings (WAL, synchronous=FULL, foreign_keys, busy_timeout, temp_store), statements prepared once;
// - one committed measurement with synchronous=FULL (colorlab's choice) vs NORMAL vs a batched
//   transaction (QCoDeS's fix for slow inserts, PR #1187);
// - a page of runs deep in a 20 000-run catalogue: keyset (colorlab) vs OFFSET (QCoDeS #1915).
// Runs interleaved by default (5 repetitions, random interleaving), so every comparison is made in one run
// under the same load; flags given on the command line override these defaults.
#include <benchmark/benchmark.h>
#include <fcntl.h>
#include <sqlite3.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "colorlab/store/store.hpp"
#include "colorlab/testing/temp_dir.hpp"

namespace {

void BM_CommitMeasurement_Full(benchmark::State& state) {
  colorlab::testing::TempDir dir;
  colorlab::store::Store store(dir / "colorlab.db");
  colorlab::store::NewRun run{"luminance-spot", nlohmann::json::object(), true, nlohmann::json::array(), std::nullopt};
  auto e = store.create_execution(run).execution;
  long i = 0;
  for (auto _ : state) {
    store.add_measurement(e.run_id, "reading/" + std::to_string(i++), "ls110", true, "luminance", 245.3, "cd/m2",
                          {{"raw", "OK00,   245.30"}});
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_CommitMeasurement_Full)->Unit(benchmark::kMicrosecond);

// One campaign step as the engine commits it: a journal entry, a measurement, the progress and the
// event in one transaction (synchronous=FULL). The issue's target: within 2× of this machine's
// fdatasync, measured beside it in the same run (BM_Fdatasync4k).
colorlab::store::NewRun bench_run() {
  colorlab::store::NewRun run{"luminance-spot", nlohmann::json::object(), true, nlohmann::json::array(), std::nullopt};
  run.script_sha256 = "bench";
  run.script_source = "return {}";
  return run;
}

class StoreStepWriter {
 public:
  explicit StoreStepWriter(const std::filesystem::path& db) : store_(db), e_(store_.create_execution(bench_run()).execution) {}
  void commit() {
    colorlab::store::StepRecord step;
    nlohmann::json result{{"luminance", 245.3}, {"unit", "cd/m2"}, {"instrument", "ls110"}, {"raw", "OK00,   245.30"}};
    step.journal.push_back({i_, "meter.measure", nlohmann::json::array(), result});
    step.measurements.push_back({
        "reading/" + std::to_string(i_),
        "ls110",
        true,
        "luminance",
        245.3,
        "cd/m2",
        {{"raw", "OK00,   245.30"}},
    });
    step.progress = 0.5;
    step.step = "reading/" + std::to_string(i_);
    store_.commit_step(e_, step);
    ++i_;
  }

 private:
  colorlab::store::Store store_;
  colorlab::store::ExecutionRecord e_;
  std::int64_t i_ = 0;
};

void BM_CommitCampaignStep_Full(benchmark::State& state) {
  colorlab::testing::TempDir dir;
  StoreStepWriter store(dir / "colorlab.db");
  for (auto _ : state) store.commit();
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_CommitCampaignStep_Full)->Unit(benchmark::kMicrosecond);

// The floor any durable commit stands on: 4 KiB appended and fdatasync'd in the same directory.
void BM_Fdatasync4k(benchmark::State& state) {
  colorlab::testing::TempDir dir;
  int fd = ::open((dir / "sync.bin").c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  std::string block(4096, 'x');
  for (auto _ : state) {
    if (::write(fd, block.data(), block.size()) != static_cast<ssize_t>(block.size())) state.SkipWithError("write");
    ::fdatasync(fd);
  }
  ::close(fd);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Fdatasync4k)->Unit(benchmark::kMicrosecond);

// The store's connection settings (daemon/store/src/store.cpp), with the given synchronous level.
void store_settings(sqlite3* db, const char* sync) {
  for (std::string pragma : {"PRAGMA busy_timeout = 5000", "PRAGMA journal_mode = WAL", "PRAGMA foreign_keys = ON",
                             "PRAGMA journal_size_limit = 67108864", "PRAGMA temp_store = MEMORY"}) {
    sqlite3_exec(db, pragma.c_str(), nullptr, nullptr, nullptr);
  }
  sqlite3_exec(db, (std::string("PRAGMA synchronous = ") + sync).c_str(), nullptr, nullptr, nullptr);
}

// The reference for BM_CommitCampaignStep_Full: the same step's rows and statements (journal entry, measurement
// with its sequence number, the execution's progress, the event) in one transaction through raw SQLite, on the
// store's own schema with the store's settings, every statement prepared once and the JSON texts made once.
class RawStepWriter {
 public:
  explicit RawStepWriter(const std::filesystem::path& path) {
    {
      colorlab::store::Store store(path);  // schema and one execution, then closed
      e_ = store.create_execution(bench_run()).execution;
    }
    sqlite3_open(path.c_str(), &db_);
    store_settings(db_, "FULL");
    begin_ = prepare("BEGIN");
    commit_ = prepare("COMMIT");
    journal_ = prepare("INSERT INTO journal (execution_id, seq, call, args, result, at) VALUES (?1, ?2, 'meter.measure', '[]', ?3, ?4)");
    max_seq_ = prepare("SELECT COALESCE(MAX(seq), 0) FROM measurements WHERE run_id = ?1");
    measurement_ = prepare(
        "INSERT INTO measurements (run_id, seq, step, instrument_id, simulated, quantity, value, unit, data, measured_at) "
        "VALUES (?1, ?2, ?3, 'ls110', 1, 'luminance', 245.3, 'cd/m2', ?4, ?5)");
    progress_ = prepare(
        "UPDATE executions SET progress = 0.5, step = ?2, updated_at = ?3, steps_committed = steps_committed + 1, "
        "resume_attempts = 0 WHERE id = ?1");
    event_ = prepare("INSERT INTO event_log (time, topic, payload) VALUES (?1, 'progress', ?2)");
  }
  ~RawStepWriter() {
    for (auto* st : {begin_, commit_, journal_, max_seq_, measurement_, progress_, event_}) sqlite3_finalize(st);
    sqlite3_close(db_);
  }
  RawStepWriter(const RawStepWriter&) = delete;
  RawStepWriter& operator=(const RawStepWriter&) = delete;
  bool ok() const { return ok_; }

  void commit() {
    const std::string step = "reading/" + std::to_string(i_);
    const std::string payload = R"({"execution_id":")" + e_.id + R"(","measurements":1,"progress":0.5,"run_id":")" +
                                e_.run_id + R"(","step":")" + step + R"("})";
    run(begin_);
    sqlite3_bind_text(journal_, 1, e_.id.c_str(), -1, SQLITE_STATIC);
    sqlite3_bind_int64(journal_, 2, i_);
    sqlite3_bind_text(journal_, 3, result_.c_str(), -1, SQLITE_STATIC);
    sqlite3_bind_text(journal_, 4, now_.c_str(), -1, SQLITE_STATIC);
    run(journal_);
    sqlite3_bind_text(max_seq_, 1, e_.run_id.c_str(), -1, SQLITE_STATIC);
    const std::int64_t seq = sqlite3_step(max_seq_) == SQLITE_ROW ? sqlite3_column_int64(max_seq_, 0) : 0;
    sqlite3_reset(max_seq_);
    sqlite3_bind_text(measurement_, 1, e_.run_id.c_str(), -1, SQLITE_STATIC);
    sqlite3_bind_int64(measurement_, 2, seq + 1);
    sqlite3_bind_text(measurement_, 3, step.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(measurement_, 4, data_.c_str(), -1, SQLITE_STATIC);
    sqlite3_bind_text(measurement_, 5, now_.c_str(), -1, SQLITE_STATIC);
    run(measurement_);
    sqlite3_bind_text(progress_, 1, e_.id.c_str(), -1, SQLITE_STATIC);
    sqlite3_bind_text(progress_, 2, step.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(progress_, 3, now_.c_str(), -1, SQLITE_STATIC);
    run(progress_);
    sqlite3_bind_text(event_, 1, now_.c_str(), -1, SQLITE_STATIC);
    sqlite3_bind_text(event_, 2, payload.c_str(), -1, SQLITE_TRANSIENT);
    run(event_);
    run(commit_);
    ++i_;
  }

 private:
  sqlite3_stmt* prepare(const char* sql) {
    sqlite3_stmt* st = nullptr;
    if (sqlite3_prepare_v2(db_, sql, -1, &st, nullptr) != SQLITE_OK) ok_ = false;
    return st;
  }
  static void run(sqlite3_stmt* st) {
    while (sqlite3_step(st) == SQLITE_ROW) {
    }
    sqlite3_reset(st);
  }

  sqlite3* db_ = nullptr;
  bool ok_ = true;
  colorlab::store::ExecutionRecord e_;
  sqlite3_stmt *begin_ = nullptr, *commit_ = nullptr, *journal_ = nullptr, *max_seq_ = nullptr, *measurement_ = nullptr,
               *progress_ = nullptr, *event_ = nullptr;
  const std::string result_ = R"({"instrument":"ls110","luminance":245.3,"raw":"OK00,   245.30","unit":"cd/m2"})";
  const std::string data_ = R"({"raw":"OK00,   245.30"})";
  const std::string now_ = "2026-11-24T00:00:00.000Z";
  std::int64_t i_ = 0;
};

void BM_RawStep_Full(benchmark::State& state) {
  colorlab::testing::TempDir dir;
  RawStepWriter raw(dir / "colorlab.db");
  if (!raw.ok()) state.SkipWithError("could not prepare the raw step's statements");
  for (auto _ : state) raw.commit();
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RawStep_Full)->Unit(benchmark::kMicrosecond);

// The store's step and the raw step alternating commit by commit (store, raw, raw, store, ...), each timed alone,
// in two databases in the same directory: the disk's moment-to-moment noise falls on both alike. Counters: each
// side's median commit (µs) and their ratio.
void BM_StepVsRawStep_Alternating(benchmark::State& state) {
  colorlab::testing::TempDir dir;
  StoreStepWriter store(dir / "store.db");
  RawStepWriter raw(dir / "raw.db");
  if (!raw.ok()) state.SkipWithError("could not prepare the raw step's statements");
  std::vector<double> t_store, t_raw;
  std::int64_t k = 0;
  for (auto _ : state) {
    auto timed = [](auto& writer) {
      auto t0 = std::chrono::steady_clock::now();
      writer.commit();
      return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
    };
    if (k++ % 2 == 0) {
      t_store.push_back(timed(store));
      t_raw.push_back(timed(raw));
    } else {
      t_raw.push_back(timed(raw));
      t_store.push_back(timed(store));
    }
    state.SetIterationTime((t_store.back() + t_raw.back()) / 1e6);
  }
  auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  if (!t_store.empty()) {
    state.counters["store_us"] = median(t_store);
    state.counters["raw_us"] = median(t_raw);
    state.counters["store_per_raw"] = median(t_store) / median(t_raw);
  }
}
BENCHMARK(BM_StepVsRawStep_Alternating)->UseManualTime()->Unit(benchmark::kMicrosecond)->MinTime(2.0);

// One row per commit through raw SQLite with the store's settings: FULL (durable), NORMAL (no fsync per
// commit) and one transaction for all.
void raw_inserts(benchmark::State& state, const char* sync, bool batched) {
  colorlab::testing::TempDir dir;
  sqlite3* db = nullptr;
  sqlite3_open((dir / "raw.db").c_str(), &db);
  store_settings(db, sync);
  sqlite3_exec(db, "CREATE TABLE m(run TEXT, seq INT, step TEXT, value REAL, data TEXT, PRIMARY KEY(run, step)) WITHOUT ROWID",
               nullptr, nullptr, nullptr);
  sqlite3_stmt* st = nullptr;
  sqlite3_prepare_v2(db, "INSERT INTO m VALUES ('r', ?1, ?2, 245.3, '{\"raw\":\"OK00,   245.30\"}')", -1, &st, nullptr);
  long i = 0;
  if (batched) sqlite3_exec(db, "BEGIN", nullptr, nullptr, nullptr);
  for (auto _ : state) {
    std::string step = "reading/" + std::to_string(i);
    sqlite3_bind_int64(st, 1, i++);
    sqlite3_bind_text(st, 2, step.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_step(st);
    sqlite3_reset(st);
  }
  if (batched) sqlite3_exec(db, "COMMIT", nullptr, nullptr, nullptr);
  sqlite3_finalize(st);
  sqlite3_close(db);
  state.SetItemsProcessed(state.iterations());
}
void BM_RawInsert_Normal(benchmark::State& s) { raw_inserts(s, "NORMAL", false); }
// colorlab's settings on raw SQLite (WAL, FULL, one row per commit): the reference for the store's own cost.
void BM_RawInsert_Full(benchmark::State& s) { raw_inserts(s, "FULL", false); }
BENCHMARK(BM_RawInsert_Full)->Unit(benchmark::kMicrosecond);
void BM_RawInsert_OneTransaction(benchmark::State& s) { raw_inserts(s, "FULL", true); }
BENCHMARK(BM_RawInsert_Normal)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RawInsert_OneTransaction)->Unit(benchmark::kMicrosecond);

struct Catalogue {
  colorlab::testing::TempDir dir;
  std::unique_ptr<colorlab::store::Store> store;
  Catalogue() {
    store = std::make_unique<colorlab::store::Store>(dir / "colorlab.db");
    sqlite3* db = nullptr;
    sqlite3_open((dir / "colorlab.db").c_str(), &db);
    sqlite3_exec(db, "BEGIN", nullptr, nullptr, nullptr);
    for (int i = 0; i < 20000; ++i) {
      std::string sql = "INSERT INTO runs (id, campaign, params, status, simulated, instruments, created_at) VALUES ('run-" +
                        std::to_string(i) + "', 'luminance-spot', '{}', 'finished_ok', 1, '[]', '2026-11-22T00:00:00.000Z')";
      sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr);
    }
    sqlite3_exec(db, "COMMIT", nullptr, nullptr, nullptr);
    sqlite3_close(db);
  }
};

Catalogue& catalogue() {
  static Catalogue c;
  return c;
}

void BM_RunsPage_Keyset_Deep(benchmark::State& state) {
  auto& c = catalogue();
  for (auto _ : state) benchmark::DoNotOptimize(c.store->runs(50, std::string("1000")));
}
BENCHMARK(BM_RunsPage_Keyset_Deep)->Unit(benchmark::kMicrosecond);

void BM_RunsPage_Offset_Deep(benchmark::State& state) {
  auto& c = catalogue();
  sqlite3* db = nullptr;
  sqlite3_open_v2((c.dir / "colorlab.db").c_str(), &db, SQLITE_OPEN_READONLY, nullptr);
  sqlite3_stmt* st = nullptr;
  sqlite3_prepare_v2(db, "SELECT seq, id, campaign, params, status FROM runs ORDER BY seq DESC LIMIT 50 OFFSET 18950", -1,
                     &st, nullptr);
  for (auto _ : state) {
    while (sqlite3_step(st) == SQLITE_ROW) benchmark::DoNotOptimize(sqlite3_column_int64(st, 0));
    sqlite3_reset(st);
  }
  sqlite3_finalize(st);
  sqlite3_close(db);
}
BENCHMARK(BM_RunsPage_Offset_Deep)->Unit(benchmark::kMicrosecond);

}  // namespace

int main(int argc, char** argv) {
  // Interleaved repetitions unless the command line says otherwise (later flags win).
  std::vector<char*> args{argv[0]};
  std::string reps = "--benchmark_repetitions=5", interleave = "--benchmark_enable_random_interleaving=true";
  args.push_back(reps.data());
  args.push_back(interleave.data());
  for (int i = 1; i < argc; ++i) args.push_back(argv[i]);
  int n = static_cast<int>(args.size());
  benchmark::Initialize(&n, args.data());
  if (benchmark::ReportUnrecognizedArguments(n, args.data())) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
