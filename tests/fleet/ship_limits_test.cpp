// [ship]'s transaction limits (docs/fleet.md, "Transaction limits"): their defaults, their accepted range, and a
// value out of range refused with the file, the line and the key.
#include <gtest/gtest.h>

#include <fstream>

#include "colorlab/core/error.hpp"
#include "colorlab/fleet/config.hpp"
#include "colorlab/testing/temp_dir.hpp"

namespace fs = std::filesystem;
using colorlab::fleet::load_ship_config;

namespace {

fs::path write_config(const fs::path& dir, const std::string& extra) {
  const fs::path file = dir / "colorlabd.toml";
  std::ofstream(file) << "state_dir = \"" << (dir / "state").string() << "\"\n[ship]\nbench_id = \"bench-1\"\n"
                      << "postgres = \"host=127.0.0.1 dbname=colorlab\"\ns3_endpoint = \"http://127.0.0.1:9\"\n"
                      << "bucket = \"colorlab\"\naccess_key_file = \"ak\"\nsecret_key_file = \"sk\"\n"
                      << extra;
  return file;
}

TEST(FleetShipLimits, DefaultsAreTheDocumentedOnes) {
  colorlab::testing::TempDir dir;
  const auto c = load_ship_config(write_config(dir.path(), ""));
  EXPECT_EQ(c.transaction_runs, 100);
  EXPECT_EQ(c.transaction_measurements, 200000);
}

TEST(FleetShipLimits, OneRunATransactionAndTheBoundsAreAccepted) {
  colorlab::testing::TempDir dir;
  auto c = load_ship_config(write_config(dir.path(), "transaction_runs = 1\ntransaction_measurements = 1\n"));
  EXPECT_EQ(c.transaction_runs, 1);
  EXPECT_EQ(c.transaction_measurements, 1);
  c = load_ship_config(write_config(dir.path(), "transaction_runs = 10000\ntransaction_measurements = 10000000\n"));
  EXPECT_EQ(c.transaction_runs, 10000);
  EXPECT_EQ(c.transaction_measurements, 10000000);
}

TEST(FleetShipLimits, OutOfRangeIsRefusedWithFileLineAndKey) {
  colorlab::testing::TempDir dir;
  for (const std::string bad : {"transaction_runs = 0\n", "transaction_runs = 10001\n", "transaction_runs = \"many\"\n",
                                "transaction_measurements = 0\n", "transaction_measurements = 10000001\n"}) {
    const fs::path file = write_config(dir.path(), bad);
    try {
      load_ship_config(file);
      FAIL() << "accepted " << bad;
    } catch (const colorlab::Error& e) {
      const std::string what = e.what();
      const std::string key = bad.substr(0, bad.find(' '));
      EXPECT_EQ(e.cls(), colorlab::ErrorClass::bad_parameter) << what;
      EXPECT_NE(what.find(file.string() + ":9:"), std::string::npos) << what;
      EXPECT_NE(what.find("ship." + key), std::string::npos) << what;
    }
  }
}

}  // namespace
