// A verification stored like a run: read back through the store's own queries, as GET /v1/runs/{id} does.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <string>

#include <sqlite3.h>

#include "colorlab/core/error.hpp"
#include "store_verification.hpp"

namespace colorlab::verify {
namespace {

std::filesystem::path fresh_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / (name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// A flat 20 × 10 XYZ rendering at Y = 50.
Rendering flat_rendering() {
  Rendering r;
  r.width = 20;
  r.height = 10;
  r.encoding = Encoding::xyz;
  r.pixels.assign(20 * 10 * 3, 50.0f);
  return r;
}

TEST(VerifyStore, ReadBackAsARun) {
  const auto dir = fresh_dir("verify-store");
  const Rendering r = flat_rendering();
  MeasuredScene m;
  for (int i = 0; i < 2; ++i) {
    SpotMeasurement s;
    s.col = i;
    s.luminance_cd_m2 = i ? 80 : 100;
    s.reading_sd = 1;
    s.rendering_region = {2 + 10 * i, 2, 4, 4};
    m.spots.push_back(s);
  }
  CompareOptions o;
  o.scale = 2.0;
  const auto v = compare(r, m, o);
  std::string id;
  {
    store::Store st(dir / "colorlab.db");
    id = store_verification(st, to_store(v, "render.exr", {"run-a"}, o));
  }
  store::Store st(dir / "colorlab.db", store::Store::ReadOnly{});
  const auto run = st.run(id);
  ASSERT_TRUE(run.has_value());
  EXPECT_EQ(run->campaign, "verify");
  EXPECT_EQ(run->status, "finished_ok");
  EXPECT_EQ(run->summary["verdict"], "differs");
  EXPECT_EQ(run->params["against"][0], "run-a");
  const auto rows = st.measurements(id);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[1].step, "light_spot/r0c1");
  EXPECT_EQ(rows[1].data["verdict"], "differs");
  std::filesystem::remove_all(dir);
}

// A write that fails after the execution was created (a trigger stands in for the disk refusing the rows): the
// error reaches the caller, and the execution is ended, not left unfinished to hold the lab (one execution at a time)
// until the next start-up.
TEST(VerifyStore, AFailedWriteLeavesNoUnfinishedExecution) {
  const auto dir = fresh_dir("verify-store-fail");
  const Rendering r = flat_rendering();
  MeasuredScene m;
  SpotMeasurement s;
  s.luminance_cd_m2 = 100;
  s.reading_sd = 1;
  s.rendering_region = {2, 2, 4, 4};
  m.spots.push_back(s);
  CompareOptions o;
  o.scale = 2.0;
  const auto v = compare(r, m, o);
  {
    store::Store st(dir / "colorlab.db");
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open((dir / "colorlab.db").c_str(), &db), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(db, "CREATE TRIGGER refuse BEFORE INSERT ON measurements BEGIN SELECT RAISE(ABORT, 'refused'); END",
                           nullptr, nullptr, nullptr),
              SQLITE_OK);
    sqlite3_close(db);
    EXPECT_THROW(store_verification(st, to_store(v, "render.exr", {"run-a"}, o)), colorlab::Error);
    EXPECT_TRUE(st.unfinished_executions().empty());
  }
  store::Store st(dir / "colorlab.db", store::Store::ReadOnly{});
  const auto page = st.runs(10, std::nullopt);
  ASSERT_EQ(page.runs.size(), 1u);
  EXPECT_EQ(page.runs[0].status, "finished_error");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace colorlab::verify
