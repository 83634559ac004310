// The imaging luminance meter's arithmetic (floor_luminance.hpp) on analytic cases: a homography through four corners
// maps every floor point exactly, the flat field's coefficients come back from exact data, and the robust spot value
// leaves out hot, dead and dust-shadowed pixels but keeps the noise of the good ones.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "colorlab/analysis/floor_luminance.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::analysis {
namespace {

// A perspective view of a 1200 × 600 floor: x' = (a·x + b·y + c) / (g·x + h·y + 1), …
std::array<double, 2> view(double x, double y) {
  const double w = 1 + 2e-4 * y;
  return {(2.5 * x + 0.3 * y + 100) / w, (-1.8 * y + 1500) / w};
}

TEST(FloorMap, MapsEveryPointOfAPerspectiveViewThroughItsCorners) {
  const FloorMap map({view(0, 0), view(1200, 0), view(1200, 600), view(0, 600)}, 1200, 600);
  for (double x : {0.0, 30.0, 570.0, 1199.0})
    for (double y : {0.0, 27.0, 405.0, 600.0}) {
      const auto p = map.pixel_of(x, y), q = view(x, y);
      EXPECT_NEAR(p[0], q[0], 1e-6);
      EXPECT_NEAR(p[1], q[1], 1e-6);
      const auto back = map.floor_of(p[0], p[1]);
      EXPECT_NEAR(back[0], x, 1e-6);
      EXPECT_NEAR(back[1], y, 1e-6);
    }
}

TEST(FloorMap, RefusesCornersOutOfOrder) {
  EXPECT_THROW(FloorMap({view(0, 0), view(1200, 600), view(1200, 0), view(0, 600)}, 1200, 600), Error);
  EXPECT_THROW(FloorMap({view(0, 0), view(1200, 0), view(1200, 600), view(0, 600)}, 0, 600), Error);
}

TEST(FlatField, ExactDataGivesTheCoefficientsBack) {
  const int w = 3504, h = 2336;
  const double c0 = 0.34, c1 = 0.23, c2 = 0.05, cx = (w - 1) / 2.0, cy = (h - 1) / 2.0, r = std::hypot(w / 2.0, h / 2.0);
  std::vector<FlatFieldSample> cal;
  for (auto [x, y] : std::vector<std::pair<double, double>>{{1750, 1200}, {150, 1800}, {3000, 700}, {500, 650}, {2800, 1800}}) {
    const double rho2 = ((x - cx) * (x - cx) + (y - cy) * (y - cy)) / (r * r);
    const double signal = 900 - 0.1 * x;  // any positive signal: luminance = signal · gain
    cal.push_back({x, y, signal, signal * (c0 + c1 * rho2 + c2 * rho2 * rho2)});
  }
  const auto fit = fit_flat_field(cal, w, h, 2);
  ASSERT_EQ(fit.degree, 2);
  EXPECT_NEAR(fit.coefficients[0], c0, 1e-9);
  EXPECT_NEAR(fit.coefficients[1], c1, 1e-9);
  EXPECT_NEAR(fit.coefficients[2], c2, 1e-9);
  for (double res : fit.residual_pct) EXPECT_NEAR(res, 0, 1e-7);
  // Fewer spots than terms: the degree drops to what they determine; one spot is a gain.
  const auto gain = fit_flat_field(std::span(cal).first(1), w, h, 2);
  EXPECT_EQ(gain.degree, 0);
  EXPECT_NEAR(gain.luminance(cal[0].x_px, cal[0].y_px, cal[0].signal), cal[0].luminance, 1e-9);
  EXPECT_THROW(fit_flat_field({}, w, h, 1), Error);
  std::vector<FlatFieldSample> dark{{10, 10, 0, 5}};
  EXPECT_THROW(fit_flat_field(dark, w, h, 0), Error);
}

TEST(RobustSpotValue, LeavesOutDefectsAndDustKeepsTheNoise) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(500, 5);  // 1 % noise on 500 DN
  std::vector<double> px;
  for (int i = 0; i < 400; ++i) px.push_back(noise(rng));
  double mean = 0;
  for (double v : px) mean += v / double(px.size());
  auto clean = px;
  px.push_back(3000);                                           // hot
  px.push_back(0);                                              // dead
  for (int i = 0; i < 12; ++i) px.push_back(0.7 * noise(rng));  // a dust shadow's 30 %
  const SpotValue v = robust_spot_value(px);
  EXPECT_EQ(v.total, px.size());
  EXPECT_EQ(v.used, clean.size());
  EXPECT_NEAR(v.value, mean, 1e-9);
  EXPECT_NEAR(v.stdev, 5, 0.5);
  EXPECT_THROW(robust_spot_value(std::vector<double>{}), Error);
}

}  // namespace
}  // namespace colorlab::analysis
