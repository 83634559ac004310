// colorlabd's blob retention with shipping on (docs/fleet.md): a blob goes only when every run that references it
// ended at or before the position colorlab-ship noted, so housekeeping never removes what central lacks.
#include <gtest/gtest.h>

#include <unistd.h>

#include "colorlab/fleet/bench_reader.hpp"
#include "colorlab/store/blob_index.hpp"
#include "sim_bench.hpp"

namespace fs = std::filesystem;
using namespace colorlab;
using protocol::ExecutionStatus;

namespace {

constexpr const char* kFarFuture = "9999-01-01T00:00:00.000Z";  // every blob is past its retention

TEST(FleetRetention, KeepsEveryBlobOfARunNotYetShipped) {
  const fs::path dir = fs::temp_directory_path() / ("colorlab-fleet-retention-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  {
    fleet_test::SimBench bench(dir, "bench-r", 7);
    const std::string first = bench.run_campaign(ExecutionStatus::finished_ok, 10, 5);
    const std::string open = bench.run_campaign(ExecutionStatus::finished_ok, 10, 5, false);
    store::BlobIndex index(bench.store());

    EXPECT_EQ(index.expired(kFarFuture, {}).size(), 4u) << "without shipping, retention sees every blob";
    EXPECT_TRUE(index.expired(kFarFuture, {}, 0).empty()) << "nothing shipped: nothing may go";

    fleet::BenchReader reader(bench.database());
    auto ended = reader.ended_after(0, 10);
    ASSERT_EQ(ended.size(), 1u);
    EXPECT_TRUE(index.expired(kFarFuture, {}, ended[0].ended_event - 1).empty()) << "one event short of shipped";
    auto shipped = index.expired(kFarFuture, {}, ended[0].ended_event);
    ASSERT_EQ(shipped.size(), 2u);
    for (const auto& b : shipped) {
      ASSERT_EQ(b.references.size(), 1u);
      EXPECT_EQ(b.references[0].rfind(first, 0), 0u) << "a blob of the running run would go: " << b.references[0];
    }

    bench.finish(open, ExecutionStatus::aborted);
    ended = reader.ended_after(0, 10);
    ASSERT_EQ(ended.size(), 2u);
    EXPECT_EQ(index.expired(kFarFuture, {}, ended[0].ended_event).size(), 2u);
    EXPECT_EQ(index.expired(kFarFuture, {}, ended[1].ended_event).size(), 4u);
  }
  fs::remove_all(dir);
}

}  // namespace
