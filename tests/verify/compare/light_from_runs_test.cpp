// The light half of the measured scene read from measurement rows shaped as cabinet-grid.lua and
// floor-luminance.lua record them (step keys and data fields as docs/campaigns.md states them).
#include <gtest/gtest.h>

#include <cmath>

#include "colorlab/core/error.hpp"
#include "colorlab/verify/compare/light_from_runs.hpp"

namespace colorlab::verify {
namespace {

nlohmann::json grid_row(int r, int c, std::vector<double> readings, const char* lamp = "CWF") {
  double mean = 0;
  for (double x : readings) mean += x;
  mean /= static_cast<double>(readings.size());
  return {{"step", std::string("L/") + lamp + "/D100/r" + std::to_string(r) + "c" + std::to_string(c)},
          {"quantity", "luminance"},
          {"value", mean},
          {"unit", "cd/m2"},
          {"data", {{"row", r}, {"col", c}, {"lamp", lamp}, {"dimmer_percent", 100}, {"readings", readings}}}};
}

PixelRect at_grid(int row, int col) { return {10 * col, 10 * row, 3, 3}; }

TEST(VerifyLightFromRuns, CabinetGridSpotsWithPooledRepeatability) {
  // Two spots, two readings each; relative deviations ±0.5 % and ±1 %: pooled σ = √((2·0.005² + 2·0.01²)/2).
  std::vector<nlohmann::json> rows{
      grid_row(0, 0, {99.5, 100.5}),
      grid_row(1, 2, {198, 202}),
      grid_row(0, 0, {5, 5}, "D65"),
      {{"step", "L/CWF/D50/r0c0"}, {"value", 50.0}},
  };
  MeasuredScene s;
  add_cabinet_grid(s, rows, {"CWF", 100}, at_grid);
  ASSERT_EQ(s.spots.size(), 2u);
  EXPECT_DOUBLE_EQ(s.spots[1].luminance_cd_m2, 200.0);
  EXPECT_EQ(s.spots[1].readings, 2);
  EXPECT_EQ(s.spots[1].rendering_region.x, 20);
  EXPECT_EQ(s.spots[1].rendering_region.y, 10);
  const double pooled = std::sqrt((2 * 0.005 * 0.005 + 2 * 0.01 * 0.01) / 2);
  EXPECT_NEAR(s.spots[1].reading_sd, pooled * 200, 1e-9);
  EXPECT_DOUBLE_EQ(s.lamp_drift_bound, kLampDriftBound);
  EXPECT_EQ(s.lamp, "CWF");
}

TEST(VerifyLightFromRuns, FloorMapWithItsFlatFieldResidual) {
  std::vector<nlohmann::json> rows{
      {
          {"step", "P/CWF/D100"},
          {"quantity", "floor_photograph"},
          {"data", {{"grid_rows", 8}, {"grid_cols", 10}, {"calibration", {{{"residual_pct", 1.0}}, {{"residual_pct", -2.0}}}}}},
      },
      {{"step", "F/CWF/D100/r3c4"}, {"value", 150.0}},
      {{"step", "F/CWF/D100/r3c4x"}, {"value", 1.0}},
      {{"step", "C/CWF/D100/r4c4"}, {"value", 120.0}}};
  MeasuredScene s;
  add_floor_luminance(s, rows, {"CWF", 100}, at_grid);
  ASSERT_EQ(s.floor.size(), 1u);
  EXPECT_EQ(s.floor[0].row, 3);
  EXPECT_EQ(s.floor[0].col, 4);
  EXPECT_NEAR(s.floor[0].relative_sd, std::sqrt((0.01 * 0.01 + 0.02 * 0.02) / 2), 1e-12);
  EXPECT_EQ(s.floor_rows, 8);
  EXPECT_EQ(s.floor_cols, 10);
}

TEST(VerifyLightFromRuns, TypedErrors) {
  MeasuredScene s;
  try {
    add_cabinet_grid(s, {grid_row(0, 0, {1, 1})}, {"TL84", 100}, at_grid);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::not_found);
    EXPECT_FALSE(e.hint().empty());
  }
  try {
    add_floor_luminance(s, {{{"step", "F/D65/D100/r0c0"}, {"value", 1.0}}}, {"D65", 100}, at_grid);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::bad_data);
  }
}

}  // namespace
}  // namespace colorlab::verify
