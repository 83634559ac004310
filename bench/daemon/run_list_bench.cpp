// GET /v1/runs against the runs kept (issue 27: its p99 rose 132 -> 237 -> 625 ms over three soak nights).
// The route's work, without HTTP: a page of 50 runs read and serialised as the route does (RunRecord::to_json,
// dump), unfiltered and filtered by a campaign 1 run in 100 belongs to, with 10, 1,000 and 10,000 runs kept,
// each finished with a script result of kScriptBytes. "Before" is the query colorlabd ran until schema 8
// (the whole summary, the script's result included, parsed and re-serialised per listed run; filters written
// "?3 = '' OR campaign = ?3", which no index serves); "after" is Store::runs. Results: docs/PERFORMANCE.md.
#include <benchmark/benchmark.h>
#include <sqlite3.h>

#include <map>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "colorlab/store/store.hpp"
#include "colorlab/testing/temp_dir.hpp"

namespace {

using nlohmann::json;

// A characterization's or a grid's result is tens of kB of JSON (matrices, per-patch errors, grid values).
constexpr int kScriptNumbers = 2000;  // ~20 kB of JSON

struct Kept {
  colorlab::testing::TempDir dir;
  std::unique_ptr<colorlab::store::Store> store;
  explicit Kept(int runs) {
    store = std::make_unique<colorlab::store::Store>(dir / "colorlab.db");
    json script = json::array();
    for (int i = 0; i < kScriptNumbers; ++i) script.push_back(i * 1.0001);
    const std::string summary = json{{"measurements", {{"luminance", {{"count", 12}, {"unit", "cd/m2"}, {"mean", 80.5}}}}},
                                     {"script", {{"values", script}}}}
                                    .dump();
    const std::string listed = json{{"measurements", {{"luminance", {{"count", 12}, {"unit", "cd/m2"}, {"mean", 80.5}}}}}}.dump();
    sqlite3* db = nullptr;
    sqlite3_open((dir / "colorlab.db").c_str(), &db);
    sqlite3_exec(db, "BEGIN", nullptr, nullptr, nullptr);
    sqlite3_stmt* st = nullptr;
    sqlite3_prepare_v2(db,
                       "INSERT INTO runs (id, campaign, params, status, simulated, instruments, created_at, finished_at, "
                       "summary, list_summary) VALUES (?1, ?2, '{\"readings\":12}', 'finished_ok', 1, "
                       "'[{\"id\":\"ls110\",\"kind\":\"ls110\"}]', '2026-11-29T00:00:00.000Z', '2026-11-29T00:01:00.000Z', ?3, ?4)",
                       -1, &st, nullptr);
    for (int i = 0; i < runs; ++i) {
      const std::string id = "run-" + std::to_string(i);
      sqlite3_bind_text(st, 1, id.c_str(), -1, SQLITE_TRANSIENT);
      sqlite3_bind_text(st, 2, i % 100 == 0 ? "verify" : "luminance-spot", -1, SQLITE_STATIC);
      sqlite3_bind_text(st, 3, summary.c_str(), -1, SQLITE_STATIC);
      sqlite3_bind_text(st, 4, listed.c_str(), -1, SQLITE_STATIC);
      sqlite3_step(st);
      sqlite3_reset(st);
    }
    sqlite3_finalize(st);
    sqlite3_exec(db, "COMMIT", nullptr, nullptr, nullptr);
    sqlite3_close(db);
  }
};

Kept& kept(int runs) {
  static std::map<int, std::unique_ptr<Kept>> all;
  auto& k = all[runs];
  if (!k) k = std::make_unique<Kept>(runs);
  return *k;
}

// As the route serialises a page.
std::size_t page_bytes(const colorlab::store::RunPage& page) {
  json items = json::array();
  for (const auto& r : page.runs) items.push_back(r.to_json());
  return json{{"items", items}}.dump().size();
}

void after(benchmark::State& state, const std::string& campaign) {
  auto& k = kept(static_cast<int>(state.range(0)));
  std::size_t bytes = 0;
  for (auto _ : state) bytes = page_bytes(k.store->runs(50, std::nullopt, {campaign, ""}));
  state.counters["page_kB"] = static_cast<double>(bytes) / 1000.0;
}

// The query and per-row work before schema 8.
void before(benchmark::State& state, const std::string& campaign) {
  auto& k = kept(static_cast<int>(state.range(0)));
  sqlite3* db = nullptr;
  sqlite3_open_v2((k.dir / "colorlab.db").c_str(), &db, SQLITE_OPEN_READONLY, nullptr);
  sqlite3_stmt* st = nullptr;
  sqlite3_prepare_v2(db,
                     "SELECT seq, id, campaign, params, status, simulated, instruments, created_at, started_at, finished_at, "
                     "summary, error, script_sha256 FROM runs WHERE seq < ?1 AND (?3 = '' OR campaign = ?3) "
                     "AND (?4 = '' OR status = ?4) ORDER BY seq DESC LIMIT ?2",
                     -1, &st, nullptr);
  auto text = [&](int c) {
    const auto* p = sqlite3_column_text(st, c);
    return p ? std::string(reinterpret_cast<const char*>(p)) : std::string();
  };
  std::size_t bytes = 0;
  for (auto _ : state) {
    sqlite3_bind_int64(st, 1, INT64_MAX);
    sqlite3_bind_int64(st, 2, 51);
    sqlite3_bind_text(st, 3, campaign.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 4, "", -1, SQLITE_STATIC);
    json items = json::array();
    while (sqlite3_step(st) == SQLITE_ROW) {
      items.push_back({
          {"id", text(1)},
          {"campaign", text(2)},
          {"params", json::parse(text(3))},
          {"status", text(4)},
          {"instruments", json::parse(text(6))},
          {"summary", json::parse(text(10))},
      });
    }
    sqlite3_reset(st);
    bytes = json{{"items", items}}.dump().size();
  }
  sqlite3_finalize(st);
  sqlite3_close(db);
  state.counters["page_kB"] = static_cast<double>(bytes) / 1000.0;
}

void BM_RunList_Before(benchmark::State& s) { before(s, ""); }
void BM_RunList_After(benchmark::State& s) { after(s, ""); }
void BM_RunList_Campaign_Before(benchmark::State& s) { before(s, "verify"); }
void BM_RunList_Campaign_After(benchmark::State& s) { after(s, "verify"); }
BENCHMARK(BM_RunList_Before)->Arg(10)->Arg(1000)->Arg(10000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RunList_After)->Arg(10)->Arg(1000)->Arg(10000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RunList_Campaign_Before)->Arg(10)->Arg(1000)->Arg(10000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RunList_Campaign_After)->Arg(10)->Arg(1000)->Arg(10000)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
