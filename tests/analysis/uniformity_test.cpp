// Cabinet uniformity (§6.2) on synthetic spot grids whose answers are known by construction.
#include <gtest/gtest.h>

#include <cmath>

#include "colorlab/analysis/statistics.hpp"
#include "colorlab/analysis/uniformity.hpp"
#include "colorlab/core/error.hpp"

namespace ca = colorlab::analysis;

namespace {

// A cabinet brightest in the middle of the front (row 7, column 9 of the left half), like the dissertation's D65.
// Checked against independent recomputation here; closed-form answers are in AnalyticTruthUniformity.*.
Eigen::MatrixXd cabinet(double scale) {
  Eigen::MatrixXd g(8, 10);
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 10; ++c) g(r, c) = scale * (170 + 150 * std::exp(-((7 - r) * (7 - r) / 30.0 + (9 - c) * (9 - c) / 20.0)));
  return g;
}

TEST(AnalysisUniformity, MirrorWindowsAndBestPlacement) {
  Eigen::MatrixXd left = cabinet(1.0);
  auto res = ca::analyse_uniformity(left);
  ASSERT_EQ(res.full.rows(), 8);
  ASSERT_EQ(res.full.cols(), 20);
  EXPECT_DOUBLE_EQ(res.full(3, 19), left(3, 0));
  EXPECT_DOUBLE_EQ(res.full(3, 10), left(3, 9));
  EXPECT_DOUBLE_EQ(res.difference.minCoeff(), 0.0);
  ASSERT_EQ(res.window_stdev.rows(), 5);
  ASSERT_EQ(res.window_stdev.cols(), 16);
  double best = INFINITY;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 16; ++j) {
      // Independent two-pass sample standard deviation of the 4×5 window.
      Eigen::MatrixXd b = res.full.block(i, j, 4, 5);
      double m = b.mean(), ss = (b.array() - m).square().sum();
      EXPECT_NEAR(res.window_stdev(i, j), std::sqrt(ss / 19.0), 1e-9);
      EXPECT_NEAR(res.window_stdev(i, j), res.window_stdev(i, 15 - j), 1e-9);  // Tables 3–6 are mirror-symmetric
      best = std::min(best, res.window_stdev(i, j));
    }
  EXPECT_DOUBLE_EQ(res.best.stdev, best);
  EXPECT_LE(res.best.col, 7);  // the first of the two mirror-image minima
}

TEST(AnalysisUniformity, DimmerProportionalityAndLampComparison) {
  auto full = ca::analyse_uniformity(cabinet(1.0));
  auto half = ca::analyse_uniformity(cabinet(0.5));
  auto check = ca::dimmer_proportionality(full.difference, half.difference, 0.5);
  EXPECT_NEAR(check.max_abs_error, 0.0, 1e-9);  // a perfectly proportional dimmer
  Eigen::MatrixXd skewed = cabinet(0.25);
  skewed(0, 0) += 3;  // one spot brighter than proportional
  auto quarter = ca::analyse_uniformity(skewed);
  auto c2 = ca::dimmer_proportionality(full.difference, quarter.difference, 0.25);
  EXPECT_NEAR(c2.max_abs_error, std::abs(c2.error.minCoeff()) > std::abs(c2.error.maxCoeff()) ? -c2.error.minCoeff() : c2.error.maxCoeff(), 1e-12);
  EXPECT_GT(c2.max_abs_error, 1.0);
  auto lamps = ca::compare_lamps({"D65", "D65 50%"}, {full, half});
  EXPECT_NEAR(lamps[1].range, lamps[0].range / 2, 1e-9);
  EXPECT_THROW(ca::dimmer_proportionality(full.difference, half.difference, 0.0), colorlab::Error);
  Eigen::MatrixXd bad = cabinet(1.0);
  bad(2, 3) = NAN;
  EXPECT_THROW(ca::analyse_uniformity(bad), colorlab::Error);
  EXPECT_THROW(ca::analyse_uniformity(Eigen::MatrixXd::Ones(2, 2)), colorlab::Error);
}

TEST(AnalysisStatistics, OneSummaryForEverything) {
  auto s = ca::summarize(std::vector<double>{4, 1, 3, 2});
  EXPECT_EQ(s.count, 4u);
  EXPECT_DOUBLE_EQ(s.min, 1);
  EXPECT_DOUBLE_EQ(s.max, 4);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_NEAR(s.stdev, std::sqrt(5.0 / 3.0), 1e-12);
  // Welford stays exact far from zero where the naive formula cancels.
  auto big = ca::summarize(std::vector<double>{1e9 + 1, 1e9 + 2, 1e9 + 3});
  EXPECT_NEAR(big.stdev, 1.0, 1e-6);
  EXPECT_THROW(ca::summarize(std::vector<double>{}), colorlab::Error);
  EXPECT_THROW(ca::summarize(std::vector<double>{1, NAN}), colorlab::Error);
}

}  // namespace
