// The light half of the measured scene read from measurement rows shaped as cabinet-grid.lua and
// floor-luminance.lua record them (step keys and data fields as docs/campaigns.md states them).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "colorlab/core/error.hpp"
#include "colorlab/verify/compare/light_from_runs.hpp"
#include "tally.hpp"

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

// --- detection over repeated draws, through the rows ------------------------------------------------------------

// The floor's luminance (cd/m²) at a pixel centre: a smooth field under one lamp, the physics the test states.
double floor_field(double x, double y) {
  const double u = (x - 50) / 50, v = (y - 40) / 40;
  return 200 * (1 - 0.3 * u * u - 0.15 * v * v + 0.05 * u);
}
bool in_region(int row, int col) { return row < 3 && col < 4; }  // the "one region": rows 0–2 × cols 0–3

// What a renderer shows (XYZ, cd/m² with scale 1): the field, the whole lamp `lamp` times as bright, the floor's
// reflectance `region` times itself in the region.
Rendering floor_rendering(double lamp, double region) {
  Rendering r;
  r.width = 100;
  r.height = 80;
  r.encoding = Encoding::xyz;
  r.pixels.resize(100 * 80 * 3);
  for (int y = 0; y < 80; ++y)
    for (int x = 0; x < 100; ++x) {
      const double v = floor_field(x + 0.5, y + 0.5) * lamp * (in_region(y / 10, x / 10) ? region : 1.0);
      float* p = r.pixels.data() + (y * 100 + x) * 3;
      p[0] = static_cast<float>(0.95 * v), p[1] = static_cast<float>(v), p[2] = static_cast<float>(1.09 * v);
    }
  return r;
}

// One draw of a cabinet-grid run (2 readings a spot, the LS-110's 0.3 % each) and a floor-luminance run (1 % per
// cell, the flat field's calibration residuals saying so) of the true field, each under a lamp that drifted
// uniformly within docs/campaigns.md's 1 % over the run — as rows, the way the runs store them.
std::vector<nlohmann::json> drawn_rows(std::mt19937_64& rng) {
  std::normal_distribution<double> n01(0, 1);
  std::uniform_real_distribution<double> drift(-kLampDriftBound, kLampDriftBound);
  const double grid_drift = drift(rng), floor_drift = drift(rng);
  nlohmann::json photo = {{"step", "P/D65/D100"}, {"quantity", "floor_photograph"}};
  photo["data"] = {{"grid_rows", 8}, {"grid_cols", 10}};
  photo["data"]["calibration"] = nlohmann::json::array({{{"residual_pct", 1.0}}, {{"residual_pct", -1.0}}});
  std::vector<nlohmann::json> rows{photo};
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 10; ++c) {
      const PixelRect g = at_grid(r, c);
      double truth = 0;
      for (int y = g.y; y < g.y + g.h; ++y)
        for (int x = g.x; x < g.x + g.w; ++x) truth += floor_field(x + 0.5, y + 0.5) / (g.w * g.h);
      const double spot = truth * (1 + grid_drift);
      rows.push_back(grid_row(r, c, {spot * (1 + 0.003 * n01(rng)), spot * (1 + 0.003 * n01(rng))}, "D65"));
      rows.push_back({{"step", "F/D65/D100/r" + std::to_string(r) + "c" + std::to_string(c)},
                      {"value", truth * (1 + floor_drift) * (1 + 0.01 * n01(rng))}});
    }
  return rows;
}

TEST(VerifyLightFromRuns, DetectionRatesOverDrawsOfTheRuns) {
  // The from-runs path (rows -> add_cabinet_grid / add_floor_luminance -> compare) over 200 draws of the runs, with
  // the scale given: the two light defects must be flagged where they are in >= 90 % of the draws in both
  // kinds (compare_defects_test's bound), and the rest — and a faithful rendering everywhere — in <= 5 % (issue 23).
  // A 5 % region against a spot's 0.6 % (drift, read as rectangular, with the LS-110's 0.2 %) and a cell's 1.2 %.
  using testing::Count;
  using testing::Tally;
  struct Case {
    const char* name;
    double lamp, region;
    bool everywhere;
  };
  for (const Case& k : {Case{"faithful", 1.0, 1.0, false}, Case{"the lamp 10 % too bright", 1.1, 1.0, true},
                        Case{"the floor's reflectance 5 % off in rows 0-2 x cols 0-3", 1.0, 1.05, false}}) {
    const Rendering rendering = floor_rendering(k.lamp, k.region);
    CompareOptions o;
    o.scale = 1.0;
    Tally t;
    std::mt19937_64 rng(2300);
    for (int d = 0; d < 200; ++d) {
      const auto rows = drawn_rows(rng);
      MeasuredScene s;
      add_cabinet_grid(s, rows, {"D65", 100}, at_grid);
      add_floor_luminance(s, rows, {"D65", 100}, at_grid);
      t.add(compare(rendering, s, o), [&](const Comparison& c) {
        if (k.everywhere) return true;
        if (k.region == 1.0) return false;
        const auto r = std::stoi(c.where.substr(1)), col = std::stoi(c.where.substr(c.where.find('c') + 1));
        return in_region(r, col);
      });
    }
    t.print(k.name);
    for (const char* kind : {"light_spot", "light_floor"}) {
      if (k.everywhere || k.region != 1.0) {
        EXPECT_GE(t.at[kind].rate(), 0.90) << k.name << " " << kind;
      }
      if (!k.everywhere) {
        EXPECT_LE(t.elsewhere[kind].rate(), 0.05) << k.name << " " << kind;
      }
    }
  }
}

}  // namespace
}  // namespace colorlab::verify
