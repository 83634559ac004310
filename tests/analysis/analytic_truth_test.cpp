// The analysis code on inputs whose answer is derived on paper (issue 12, "circular physics"): cabinet uniformity
// (§6.2), frame averaging and robust patch values (§6.1.2–6.1.3), characterization (chapter 7) and the black box
// (§7.4). Each test's comment carries its derivation; no expected value comes from the simulator, the
// dissertation's tables or a run of this code. Tests that compare the simulator with the dissertation are labelled
// `tuning` (docs/TESTING.md, "Analytic truth and tuning checks"); these are what checks the analysis.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "colorlab/analysis/blackbox.hpp"
#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/analysis/frame_accumulator.hpp"
#include "colorlab/analysis/patch_stats.hpp"
#include "colorlab/analysis/polynomial_terms.hpp"
#include "colorlab/analysis/regression.hpp"
#include "colorlab/analysis/sensitivity_prior.hpp"
#include "colorlab/analysis/uniformity.hpp"

namespace ca = colorlab::analysis;

namespace {

// ---------------------------------------------------------------------------------------------------------------
// Statistical bounds. A statistic of random input is held to its sampling distribution, never to a fudge factor:
// each bound is the two-sided 1 − kAlpha interval, so a correct implementation fails a given check for a fraction
// kAlpha of seeds, and this file's 57 such intervals together for fewer than 1 seed in 10 000 (57·10⁻⁶).
constexpr double kAlpha = 1e-6;

// (df · s² / σ²) ~ χ²(df) for the sample variance s² of df + 1 independent normal values (or the pooled variance of
// several such samples, df summed). Returns the interval for s² / σ².
std::pair<double, double> variance_ratio_bounds(double df) {
  const boost::math::chi_squared chi(df);
  return {boost::math::quantile(chi, kAlpha / 2) / df, boost::math::quantile(boost::math::complement(chi, kAlpha / 2)) / df};
}

double normal_quantile_two_sided() { return boost::math::quantile(boost::math::complement(boost::math::normal(), kAlpha / 2)); }

// ---------------------------------------------------------------------------------------------------------------
// §6.2 uniformity. analyse_uniformity measures the left half (8 × 10 spots) and mirrors it: full column c ≥ 10 is
// left column 19 − c. A 4 × 5 window on a product grid (rows i..i+3 × columns j..j+4) of a separable field
// f(r) + g(c) has sample variance (20/19)·(Var_pop f over its 4 rows + Var_pop g over its 5 columns), since on a
// product grid the row and column parts are uncorrelated.

constexpr int kRows = 8, kHalfCols = 10;

// A plane on the measured half, L = a + α·r + β·c. Rows: Var_pop of 4 consecutive integers = (4² − 1)/12 = 5/4.
// Columns inside one half (j ≤ 5 or j ≥ 10): 5 consecutive integers, (5² − 1)/12 = 2 (the mirrored half has slope −β,
// the same variance). Windows across the mirror see column values m(c) = c (c < 10) or 19 − c:
//   j = 6: {6,7,8,9,9} → Var_pop 1.36;  j = 7: {7,8,9,9,8} → 0.56;  j = 8: {8,9,9,8,7} → 0.56;  j = 9: → 1.36.
// So s²(i, j) = (20/19)(1.25 α² + V_j β²), the same on every row, and the best placement is column 7 (the first of
// the two mirror-image minima, the documented tie rule) on row 0 (all rows tie).
TEST(AnalyticTruthUniformity, PlaneOnTheMeasuredHalfHasClosedFormWindowDeviations) {
  const double a = 180, alpha = 3, beta = 7;
  Eigen::MatrixXd left(kRows, kHalfCols);
  for (int r = 0; r < kRows; ++r)
    for (int c = 0; c < kHalfCols; ++c) left(r, c) = a + alpha * r + beta * c;
  const auto res = ca::analyse_uniformity(left);
  ASSERT_EQ(res.window_stdev.rows(), 5);
  ASSERT_EQ(res.window_stdev.cols(), 16);
  auto v_col = [](int j) { return j == 7 || j == 8 ? 0.56 : j == 6 || j == 9 ? 1.36
                                                                             : 2.0; };
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 16; ++j) {
      const double expected = std::sqrt(20.0 / 19.0 * (1.25 * alpha * alpha + v_col(j) * beta * beta));
      EXPECT_NEAR(res.window_stdev(i, j), expected, 1e-12 * expected) << "window (" << i << ", " << j << ")";
    }
  EXPECT_EQ(res.best.row, 0);
  EXPECT_EQ(res.best.col, 7);
  EXPECT_NEAR(res.best.stdev, std::sqrt(20.0 / 19.0 * (1.25 * alpha * alpha + 0.56 * beta * beta)), 1e-12);
  EXPECT_DOUBLE_EQ(res.min, a);
  EXPECT_DOUBLE_EQ(res.max, a + 7 * alpha + 9 * beta);
}

// A quadratic field with its single maximum at row r0 = 5.5, column 9.5: F = A − p(r − r0)² − q(c − 9.5)². It is
// mirror-symmetric (19 − c − 9.5 = −(c − 9.5)), so the mirrored grid is this exact quadratic on all 20 columns.
// For n consecutive values with centre μ (offset from the vertex) and centred offsets d, x² = μ² + 2μd + d², and
// Var_pop(x²) = 4μ²·Var(d) + Var(d²) (the cross term vanishes by symmetry of d):
//   n = 4: Var(d) = 5/4, d² ∈ {1/4, 9/4} → Var(d²) = 1   ⇒  Var = 5μ² + 1,   μ = i + 1.5 − r0 = i − 4;
//   n = 5: Var(d) = 2,   d² ∈ {0,1,1,4,4} → Var(d²) = 2.8 ⇒ Var = 8μ² + 2.8, μ = j + 2 − 9.5 = j − 7.5.
// So s²(i, j) = (20/19)[p²(5(i − 4)² + 1) + q²(8(j − 7.5)² + 2.8)]: smallest at i = 4 and j = 7 or 8 (the window
// centred on the maximum; j = 7 is the first of the mirror-image tie). Extremes: max at (5|6, 9|10) = A − p/4 − q/4,
// min at the corners (r = 0, c = 0|19) = A − 30.25p − 90.25q.
TEST(AnalyticTruthUniformity, QuadraticFieldWindowDeviationsAndBestPlacementAtItsMaximum) {
  const double A = 320, p = 2, q = 1.5, r0 = 5.5, c0 = 9.5;
  Eigen::MatrixXd left(kRows, kHalfCols);
  for (int r = 0; r < kRows; ++r)
    for (int c = 0; c < kHalfCols; ++c) left(r, c) = A - p * (r - r0) * (r - r0) - q * (c - c0) * (c - c0);
  const auto res = ca::analyse_uniformity(left);
  for (int c = 0; c < 20; ++c) EXPECT_DOUBLE_EQ(res.full(2, c), A - p * (2 - r0) * (2 - r0) - q * (c - c0) * (c - c0)) << c;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 16; ++j) {
      const double mr = i - 4.0, mc = j - 7.5;
      const double expected = std::sqrt(20.0 / 19.0 * (p * p * (5 * mr * mr + 1) + q * q * (8 * mc * mc + 2.8)));
      EXPECT_NEAR(res.window_stdev(i, j), expected, 1e-12 * expected) << "window (" << i << ", " << j << ")";
    }
  EXPECT_EQ(res.best.row, 4);
  EXPECT_EQ(res.best.col, 7);
  EXPECT_NEAR(res.best.stdev, std::sqrt(20.0 / 19.0 * (p * p + q * q * 4.8)), 1e-12);
  EXPECT_DOUBLE_EQ(res.max, A - p / 4 - q / 4);
  EXPECT_DOUBLE_EQ(res.min, A - 30.25 * p - 90.25 * q);
  EXPECT_NEAR(res.difference.maxCoeff(), res.max - res.min, 1e-12);
}

// §6.2 (figs. 39–41): subtract each grid's minimum, scale the dimmed grid by 1/s, compare with full power. A dimmer
// whose light is exactly proportional, L_s = s·L + b (b: stray light, constant), gives difference grids
// s·(L − min L), so the scaled grid equals the full one and the error is 0 whatever b. One that delivers s' = 0.9·s
// at setting s leaves error = (L − min L)(1 − s'/s) = 0.1·(L − min L) ≥ 0: max |error| = 0.1 × the full range.
TEST(AnalyticTruthUniformity, DimmerProportionalityIsExactForProportionalLightAndMeasuresAShortfall) {
  Eigen::MatrixXd left(kRows, kHalfCols);
  for (int r = 0; r < kRows; ++r)
    for (int c = 0; c < kHalfCols; ++c) left(r, c) = 320 - 2 * (r - 5.5) * (r - 5.5) - 1.5 * (c - 9.5) * (c - 9.5);
  const auto full = ca::analyse_uniformity(left);
  const double range = full.max - full.min;
  for (double s : {0.5, 0.25, 0.15}) {
    const Eigen::MatrixXd proportional = (s * left).array() + 3.0;
    const auto low = ca::analyse_uniformity(proportional);
    const auto d = ca::dimmer_proportionality(full.difference, low.difference, s);
    EXPECT_NEAR(d.max_abs_error, 0.0, 1e-12 * range / s) << s;
    EXPECT_NEAR((d.scaled - full.difference).cwiseAbs().maxCoeff(), 0.0, 1e-12 * range / s) << s;

    const Eigen::MatrixXd short_light = (0.9 * s * left).array() + 3.0;
    const auto weak = ca::analyse_uniformity(short_light);
    const auto e = ca::dimmer_proportionality(full.difference, weak.difference, s);
    EXPECT_NEAR(e.max_abs_error, 0.1 * range, 1e-12 * range / s) << s;
    EXPECT_NEAR(e.error.maxCoeff(), 0.1 * range, 1e-12 * range / s) << s;  // full power is the brighter: error ≥ 0
    EXPECT_NEAR(e.error.minCoeff(), 0.0, 1e-12 * range / s) << s;          // at the minimum spot
  }
}

// ---------------------------------------------------------------------------------------------------------------
// §6.1.3 frame averaging.

// Sylvester's Hadamard matrix: H[i][j] = (−1)^popcount(i & j). Rows 1..n−1 have zero sum and are mutually orthogonal.
int hadamard(std::size_t i, std::size_t j) { return std::popcount(i & j) % 2 ? -1 : 1; }

// Deterministic noise with an exact answer: frame k (k = 1..N) of a 32 × 32 patch (n = 1024 pixels, index p) is
// μ + a·H[k][p]. Each frame's pixel spread is a (population). The N-frame mean is μ + (a/N)·Σ_k H[k][p]; its spatial
// mean is μ and Σ_p (Σ_k H[k][p])² = Σ_k Σ_l ⟨H_k, H_l⟩ = N·n, so its population variance is a²/N and its sample
// standard deviation exactly (a/√N)·√(n/(n − 1)): the 1/√N law holds with equality, not on average.
TEST(AnalyticTruthAveraging, HadamardNoiseMeanOfNFramesHasExactlyOneOverRootNTheSpread) {
  const std::size_t w = 40, h = 40, x0 = 4, y0 = 4, side = 32, n = side * side, frames = 25;
  const double mu = 30000, a = 100;
  std::vector<std::vector<float>> fimg(frames, std::vector<float>(w * h, static_cast<float>(mu)));
  std::vector<std::vector<std::uint16_t>> uimg(frames, std::vector<std::uint16_t>(w * h, static_cast<std::uint16_t>(mu)));
  for (std::size_t k = 0; k < frames; ++k)
    for (std::size_t y = 0; y < side; ++y)
      for (std::size_t x = 0; x < side; ++x) {
        const double v = mu + a * hadamard(k + 1, y * side + x);
        fimg[k][(y0 + y) * w + x0 + x] = static_cast<float>(v);
        uimg[k][(y0 + y) * w + x0 + x] = static_cast<std::uint16_t>(v);
      }
  auto exact = [&](std::size_t N) { return a / std::sqrt(double(N)) * std::sqrt(double(n) / double(n - 1)); };

  // The analysis' Table 2 statistic (noise_vs_averaging): the spread of the averaged patch.
  std::vector<ca::ImageView> views;
  for (const auto& f : fimg) views.push_back({f.data(), w, h, w});
  const ca::Rect patch{x0, y0, side, side};
  const auto rows = ca::noise_vs_averaging(views, std::span<const ca::Rect>(&patch, 1));
  ASSERT_EQ(rows.size(), 6u);
  for (const auto& r : rows) EXPECT_NEAR(r.patch_stdev[0], exact(r.frames), 1e-9 * exact(r.frames)) << r.frames << " frames";

  // The streaming accumulator's mean, the same spread. Its float mean rounds each pixel by at most half an ulp of
  // μ ± a (2⁻²⁴·2¹⁵ = 2⁻⁹), which moves a standard deviation by at most that much times √(n/(n − 1)).
  ca::FrameAccumulator acc(w, h);
  for (std::size_t k = 0; k < frames; ++k) {
    acc.add(uimg[k]);
    const std::size_t N = k + 1;
    if (N != 1 && N != 2 && N != 4 && N != 8 && N != 16 && N != 25) continue;
    const auto mean = acc.mean();
    std::vector<double> px;
    for (std::size_t y = 0; y < side; ++y)
      for (std::size_t x = 0; x < side; ++x) px.push_back(mean[(y0 + y) * w + x0 + x]);
    EXPECT_NEAR(ca::summarize(px).stdev, exact(N), std::ldexp(1.0, -9) * 1.001) << N << " frames";
    EXPECT_NEAR(ca::summarize(px).mean, mu, 1e-9 * mu) << N << " frames";
  }
}

// Two-level frames, the accumulator's closed form: a pixel alternating μ + a, μ − a, μ + a, … over N frames has mean
// μ (N even) or μ + a/N (N odd), and Σ(x − x̄)² = N·a² − N·(a/N)²·[N odd], so its sample standard deviation is
// a·√(N/(N − 1)) (N even) or a·√((N + 1)/N) (N odd). At full scale (μ + a = 65535) and with a = 1 over 65 536 frames
// this is where the u32/u64 sums and the n·Σx² − (Σx)² cancellation would show an error.
TEST(AnalyticTruthAveraging, AlternatingFramesGiveTheClosedFormMeanAndStdEvenAtFullScale) {
  struct Case {
    double mu, a;
  };
  for (const Case cs : {Case{65534, 1}, Case{65035, 500}, Case{1000, 3}}) {
    ca::FrameAccumulator acc(3, 2);
    std::vector<std::uint16_t> hi(6, static_cast<std::uint16_t>(cs.mu + cs.a)), lo(6, static_cast<std::uint16_t>(cs.mu - cs.a));
    for (std::size_t N = 1; N <= 65536; ++N) {
      acc.add(N % 2 ? hi : lo);
      if (!(N <= 26 || N == 1001 || N == 65535 || N == 65536)) continue;
      const double dn = static_cast<double>(N);
      const double mean = N % 2 ? cs.mu + cs.a / dn : cs.mu;
      const double sd = N == 1 ? 0.0 : N % 2 ? cs.a * std::sqrt((dn + 1) / dn)
                                             : cs.a * std::sqrt(dn / (dn - 1));
      // Float outputs: within 2 ulps of the exact value.
      EXPECT_NEAR(acc.mean()[5], mean, 2 * std::ldexp(mean, -24)) << "N " << N << " μ " << cs.mu;
      EXPECT_NEAR(acc.stddev()[0], sd, 2 * std::ldexp(sd, -24) + 1e-30) << "N " << N << " μ " << cs.mu;
    }
  }
}

// Gaussian noise of known σ, statistics held to their sampling distributions (chi-square, not a tolerance):
// • the accumulator's per-pixel sample variance over N frames: (N − 1)s²/σ_q² ~ χ²(N − 1), pooled over P pixels
//   χ²(P(N − 1)); the frames are 16-bit, so σ_q² = σ² + 1/12 (Sheppard: rounding a normal with σ ≫ 1 adds an
//   independent uniform error; the correction's error is of order e^(−2π²σ²));
// • the spread over P pixels of the accumulator's N-frame mean: (P − 1)s²/(σ_q²/N) ~ χ²(P − 1);
// • noise_vs_averaging's patch spread on float frames (no rounding), per patch of n pixels χ²(n − 1), and pooled
//   over the patches χ²(Σ(n − 1)).
TEST(AnalyticTruthAveraging, GaussianNoiseOfTheMeanOfNFramesIsSigmaOverRootNWithinChiSquareBounds) {
  const std::vector<std::size_t> subsets(ca::kTable2Subsets.begin(), ca::kTable2Subsets.end());
  {
    const std::size_t w = 64, h = 64, P = w * h, frames = 25;
    const double mu = 1000.3, sigma = 8, sq2 = sigma * sigma + 1.0 / 12;
    std::mt19937_64 rng(12);
    std::normal_distribution<double> nd(0, sigma);
    ca::FrameAccumulator acc(w, h);
    std::vector<std::uint16_t> f(P);
    for (std::size_t N = 1; N <= frames; ++N) {
      for (auto& v : f) v = static_cast<std::uint16_t>(std::lround(mu + nd(rng)));
      acc.add(f);
      if (std::find(subsets.begin(), subsets.end(), N) == subsets.end()) continue;
      const auto mean = acc.mean();
      std::vector<double> m(mean.begin(), mean.end());
      const auto [lo, hi] = variance_ratio_bounds(double(P - 1));
      const double ratio = std::pow(ca::summarize(m).stdev, 2) / (sq2 / double(N));
      EXPECT_GE(ratio, lo) << N << " frames: spread of the mean";
      EXPECT_LE(ratio, hi) << N << " frames: spread of the mean";
      if (N < 2) continue;
      double pooled = 0;
      for (float s : acc.stddev()) pooled += double(s) * double(s);
      pooled /= double(P);
      const auto [tlo, thi] = variance_ratio_bounds(double(P * (N - 1)));
      EXPECT_GE(pooled / sq2, tlo) << N << " frames: per-pixel temporal variance";
      EXPECT_LE(pooled / sq2, thi) << N << " frames: per-pixel temporal variance";
    }
  }
  {
    const std::size_t w = 100, h = 100, frames = 25;
    const double sigma = 2;
    const std::vector<ca::Rect> patches{{1, 1, 48, 48}, {51, 1, 48, 48}, {1, 51, 48, 48}, {51, 51, 48, 40}};
    const double level[4] = {80, 200, 1000, 3000};
    std::mt19937_64 rng(13);
    std::normal_distribution<double> nd(0, sigma);
    std::vector<std::vector<float>> img(frames, std::vector<float>(w * h));
    for (auto& f : img)
      for (std::size_t y = 0; y < h; ++y)
        for (std::size_t x = 0; x < w; ++x) f[y * w + x] = static_cast<float>(level[(y >= 50) * 2 + (x >= 50)] + nd(rng));
    std::vector<ca::ImageView> views;
    for (const auto& f : img) views.push_back({f.data(), w, h, w});
    const auto rows = ca::noise_vs_averaging(views, patches);
    ASSERT_EQ(rows.size(), 6u);
    for (const auto& r : rows) {
      const double var = sigma * sigma / double(r.frames);
      double pooled = 0, df = 0;
      for (std::size_t i = 0; i < patches.size(); ++i) {
        const double n = double(patches[i].width * patches[i].height);
        const auto [lo, hi] = variance_ratio_bounds(n - 1);
        const double ratio = r.patch_stdev[i] * r.patch_stdev[i] / var;
        EXPECT_GE(ratio, lo) << r.frames << " frames, patch " << i;
        EXPECT_LE(ratio, hi) << r.frames << " frames, patch " << i;
        pooled += (n - 1) * r.patch_stdev[i] * r.patch_stdev[i];
        df += n - 1;
      }
      const auto [lo, hi] = variance_ratio_bounds(df);
      EXPECT_GE(pooled / df / var, lo) << r.frames << " frames, pooled";
      EXPECT_LE(pooled / df / var, hi) << r.frames << " frames, pooled";
    }
  }
}

// ---------------------------------------------------------------------------------------------------------------
// §6.1.2 robust patch value: the mean of the pixels within ±k of the median.

// Inliers μ + d with d ∈ {−2, −1, 0, 1, 2}, 96 of each, and outliers far outside ±k (8 bit: k = 5) in unequal numbers:
// 5 dark (0) below, 15 glints (255) above. Sorted, the dark ones take ranks 1–5, μ − 2 ranks 6–101, μ − 1 102–197 and
// μ 198–293, so the median (ranks 250 and 251 of 500) is μ; the band μ ± 5 holds every inlier and no outlier, and the
// value is the inliers' mean, exactly μ.
TEST(AnalyticTruthRobustPatch, SymmetricInliersGiveTheirCentreWhateverTheOutliers) {
  const std::size_t w = 25, h = 20;  // 500 pixels
  std::vector<float> px(w * h);
  const float mu = 117;
  std::size_t up = 0, down = 0, inliers = 0;
  for (std::size_t i = 0; i < px.size(); ++i) {
    if (i % 25 == 3 && up < 15) {
      px[i] = 255, ++up;
    } else if (i % 25 == 17 && down < 5) {
      px[i] = 0, ++down;
    } else {
      px[i] = mu + static_cast<float>(static_cast<int>(inliers++ % 5) - 2);
    }
  }
  ASSERT_EQ(up, 15u);
  ASSERT_EQ(down, 5u);
  ASSERT_EQ(inliers, 480u);
  const auto pv = ca::robust_patch_value({px.data(), w, h, w}, {0, 0, w, h});
  EXPECT_DOUBLE_EQ(pv.median, mu);
  EXPECT_DOUBLE_EQ(pv.value, mu);
  EXPECT_EQ(pv.used, 480u);
}

// Averaging and the robust value together: N frames of μ + N(0, σ²) per pixel, fixed dust at 1 in 37 pixels
// (+3000 counts in every frame). Averaged, each clean pixel is N(μ, σ²/N); the band ±k = ±80 (12 bit) is ≥ 10
// standard deviations, so it keeps every clean pixel (probability of losing one < 10⁻²⁰) and no dust; the value is
// then the mean of n_clean independent N(μ, σ²/N) values: |value − μ| ≤ z·σ/√(N·n_clean).
TEST(AnalyticTruthRobustPatch, AveragedPatchValueIsWithinItsStandardErrorOfTheTruth) {
  const std::size_t w = 40, h = 30, P = w * h, frames = 16;
  const double mu = 2000.25, sigma = 8;
  std::mt19937_64 rng(14);
  std::normal_distribution<double> nd(0, sigma);
  std::vector<double> sum(P, 0.0);
  std::size_t dust = 0;
  for (std::size_t p = 0; p < P; ++p) dust += p % 37 == 5;
  const double z = normal_quantile_two_sided();
  for (std::size_t N = 1; N <= frames; ++N) {
    for (std::size_t p = 0; p < P; ++p) sum[p] += mu + nd(rng) + (p % 37 == 5 ? 3000 : 0);
    std::vector<float> avg(P);
    for (std::size_t p = 0; p < P; ++p) avg[p] = static_cast<float>(sum[p] / double(N));
    const auto pv = ca::robust_patch_value({avg.data(), w, h, w}, {0, 0, w, h}, ca::RobustOptions{12, {}});
    EXPECT_EQ(pv.used, P - dust) << N << " frames";
    EXPECT_NEAR(pv.value, mu, z * sigma / std::sqrt(double(N) * double(P - dust))) << N << " frames";
  }
}

// ---------------------------------------------------------------------------------------------------------------
// Chapter 7 characterization. A "camera" whose XYZ (or L*a*b*) is an exact polynomial of its RGB in the terms of a
// set S: least squares with S (or any superset) reproduces every patch up to round-off, so the training error and the
// leave-one-out error (each held-out patch lies on the same polynomial) are ≈ 0; any set without one of S's terms
// cannot, since that term is linearly independent of the others on the patches. Selection ("fewest terms within the
// tolerance of the best") must therefore choose S itself.
//
// Round-off: the design (4-level full factorial, 64 patches) has condition number κ < 10³ (checked), so the
// coefficients carry ≈ κ·ε relative error and the fitted XYZ about 10⁻¹¹; leave-one-out divides a residual by
// 1 − h_ii ≥ 0.5 (checked for the generating set); ΔE per XYZ unit is below 10 for Y ≥ 1 (here Y > 5). 10⁻⁶ ΔE leaves orders to spare.

ca::ChartData factorial_chart() {
  const double levels[4] = {0.1, 0.4, 0.7, 1.0};
  ca::ChartData c;
  c.rgb.resize(64, 3);
  int i = 0;
  for (double r : levels)
    for (double g : levels)
      for (double b : levels) {
        c.ids.push_back("P" + std::to_string(i + 1));
        c.rgb.row(i++) << r, g, b;
      }
  return c;
}

// Coefficients (terms × XYZ) of the generating polynomial, every term non-zero.
Eigen::MatrixXd generating_coefficients(const ca::TermSet& set) {
  Eigen::MatrixXd k(static_cast<Eigen::Index>(set.size()), 3);
  const Eigen::Matrix3d M = (Eigen::Matrix3d() << 41, 35, 18, 21, 72, 7, 2, 12, 95).finished();  // r, g, b rows
  for (std::size_t t = 0; t < set.size(); ++t) {
    const auto e = set.terms[t].exponent;
    const auto row = static_cast<Eigen::Index>(t);
    const double degree = e[0] + e[1] + e[2];
    if (degree == 1) {
      k.row(row) = M.row(e[0] == 1 ? 0 : e[1] == 1 ? 1
                                                   : 2);
    } else if (degree == 0) {
      k.row(row) << 5, 6, 4;  // a constant (flare) term
    } else {
      // Curvature of either sign, large enough that leaving a term out costs more than selection's 0.1 ΔE00
      // tolerance (asserted below as the selection's premise).
      const double s = (t % 2 ? -1 : 1) * (8 + 2 * double(t % 3));
      k.row(row) << s, 0.6 * s, -0.4 * s;
    }
  }
  return k;
}

double design_condition(const Eigen::MatrixXd& design) {
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(design);
  const auto sv = svd.singularValues();
  return sv(0) / sv(sv.size() - 1);
}

double max_leverage(const Eigen::MatrixXd& design) {
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(design);
  const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(design.rows(), design.cols());
  return Q.rowwise().squaredNorm().maxCoeff();
}

struct GeneratedCase {
  std::string truth;                 // the generating term set
  std::vector<std::string> smaller;  // sets lacking at least one of its terms
  std::vector<std::string> larger;   // supersets
};

TEST(AnalyticTruthCharacterization, ExactPolynomialCameraFitsOnlyWithItsTermsAndSelectionChoosesThem) {
  // Linear camera (the 3 × 3 matrix): nothing smaller exists. Quadratic camera (hong:10, with a constant): hong:8
  // lacks the squares, poly:5 (the dissertation's set 5) only the constant, hong:3 all but the linear terms.
  for (const GeneratedCase& cs : {GeneratedCase{"hong:3", {}, {"hong:5", "hong:10", "hong:14"}},
                                  GeneratedCase{"hong:10", {"hong:3", "hong:5", "hong:8", "poly:5"}, {"hong:11", "hong:14"}}}) {
    const ca::TermSet truth = ca::term_set_by_name(cs.truth);
    ca::ChartData xyz_chart = factorial_chart();
    const Eigen::MatrixXd design = ca::expand_terms(truth, xyz_chart.rgb);
    ASSERT_LT(design_condition(design), 1e3) << cs.truth;
    ASSERT_LT(max_leverage(design), 0.5) << cs.truth;
    xyz_chart.xyz = design * generating_coefficients(truth);
    ASSERT_GT(xyz_chart.xyz.col(1).minCoeff(), 5.0) << cs.truth << ": keep every patch's Y well above black";
    xyz_chart.lab = ca::xyz_rows_to_lab(xyz_chart.xyz, xyz_chart.white);
    // For the dissertation's direct L*a*b* regression, L*a*b* itself is the polynomial: the same one mixed by a
    // constant 3 × 3 matrix (L* = X/2, a* and b* of either sign), which keeps it in the span of the same terms.
    ca::ChartData lab_chart = xyz_chart;
    const Eigen::Matrix3d mix = (Eigen::Matrix3d() << 0.5, 0.8, 0.1, 0, -1.2, 0.6, 0, 0.4, -0.9).finished();
    lab_chart.lab = design * generating_coefficients(truth) * mix;
    for (Eigen::Index i = 0; i < lab_chart.lab.rows(); ++i) {
      const auto x = ca::lab_to_xyz({lab_chart.lab(i, 0), lab_chart.lab(i, 1), lab_chart.lab(i, 2)}, lab_chart.white);
      lab_chart.xyz.row(i) << x.X, x.Y, x.Z;
    }

    for (const auto target : {ca::FitTarget::xyz_then_lab, ca::FitTarget::xyz_lightness_weighted, ca::FitTarget::lab_direct}) {
      const ca::ChartData& data = target == ca::FitTarget::lab_direct ? lab_chart : xyz_chart;
      ca::FitOptions o;
      o.target = target;
      const std::string what = cs.truth + " " + ca::to_string(target);
      std::vector<std::string> exact{cs.truth};
      exact.insert(exact.end(), cs.larger.begin(), cs.larger.end());
      for (const auto& name : exact) {
        const auto r = ca::fit_report(ca::term_set_by_name(name), data, o, ca::CvSpec::loo());
        EXPECT_LE(r.training.s76.max, 1e-6) << what << " fitted with " << name;
        EXPECT_LE(r.cv.s76.max, 1e-6) << what << " fitted with " << name << " (leave-one-out)";
        EXPECT_LE(r.cv.s00.max, 1e-6) << what << " fitted with " << name << " (leave-one-out)";
      }
      // A set without one of the generating terms is not exact: its error is orders above round-off, and (by the
      // size of the curvature chosen above) above the selection's tolerance — the premise of the selection below.
      for (const auto& name : cs.smaller) {
        const auto r = ca::fit_report(ca::term_set_by_name(name), data, o, ca::CvSpec::loo());
        EXPECT_GT(r.training.s76.max, 1e-3) << what << " fitted with " << name;
        EXPECT_GT(r.cv.s00.mean, ca::SelectionOptions{}.tolerance_de00) << what << " fitted with " << name;
      }
      std::vector<ca::TermSet> sets;
      for (const auto& name : cs.smaller) sets.push_back(ca::term_set_by_name(name));
      for (const auto& name : exact) sets.push_back(ca::term_set_by_name(name));
      const auto sel = ca::select_model(sets, {target}, data, {}, ca::CvSpec::loo());
      EXPECT_EQ(sel.candidates[sel.chosen].method, cs.truth) << what;
      EXPECT_LE(sel.candidates[sel.best].cv.s00.mean, 1e-6) << what;
    }
  }
}

// ---------------------------------------------------------------------------------------------------------------
// §7.4 black box: RAW = spectra · s, s ≥ 0.

constexpr Eigen::Index kBands = 33;  // 400..720 nm in 10 nm steps

Eigen::MatrixXd positive_spectra(Eigen::Index n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.05, 1.0);
  Eigen::MatrixXd x(n, kBands);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index k = 0; k < kBands; ++k) x(i, k) = 50 * u(rng);  // radiance-like units
  return x;
}

// Without a prior: min ‖X s − y‖² + λ·scale·‖D s‖² over s ≥ 0, D the second difference. A sensitivity that is affine
// in wavelength has D s = 0, so with noise-free counts y = X s the true s makes both terms zero: it is a minimiser for
// every λ (and GCV's score is 0 at every λ), and the only one when no non-zero affine curve is invisible to X (checked:
// X·[1, t] has full rank). That holds with fewer patches (20) than bands (33), where X alone cannot determine s.
TEST(AnalyticTruthBlackBox, AffineSensitivitiesInThePenaltysNullSpaceAreRecoveredExactly) {
  const Eigen::MatrixXd X = positive_spectra(20, 15);
  Eigen::MatrixXd affine(kBands, 2);
  for (Eigen::Index k = 0; k < kBands; ++k) affine.row(k) << 1, double(k) / double(kBands - 1);
  ASSERT_LT(design_condition(X * affine), 1e6);
  Eigen::MatrixXd truth(3, kBands);
  for (Eigen::Index k = 0; k < kBands; ++k) {
    const double t = double(k) / double(kBands - 1);
    truth.col(k) << 100 + 900 * t, 600, 1000 - 900 * t;  // rising, flat, falling: all ≥ 100
  }
  const Eigen::MatrixXd raw = X * truth.transpose();
  for (const std::optional<double> lambda : {std::optional<double>{}, std::optional<double>{1e-3}, std::optional<double>{10.0}}) {
    ca::BlackBoxOptions o;
    o.lambda = lambda;
    const auto model = ca::fit_blackbox(X, raw, o);
    for (int c = 0; c < 3; ++c) {
      EXPECT_LE((model.sensitivities.row(c) - truth.row(c)).cwiseAbs().maxCoeff(), 1e-6 * truth.row(c).maxCoeff())
          << "RGB"[c] << " λ " << (lambda ? std::to_string(*lambda) : std::string("GCV"));
    }
  }
}

// With a prior (sensitivity_prior.hpp): s = a·mean + U·c with c ~ N(0, σ²/λ·diag(sdev²)), λ by REML. For noise-free
// counts of a curve inside that span, y = X·B·θ exactly (B = [mean, U]); the restricted likelihood then rises without
// bound as λ → 0 (q(λ) ∝ λ while the log-determinant grows only like k·log(1/λ), k < n − 1), so REML takes the bottom
// of its grid, λ = 10⁻¹⁴·d²_max, and the fit is least squares in the span up to a ridge bias of about
// λ/d²_min ≈ 10⁻¹⁴·κ(X·B)² ≤ 10⁻⁸ relative (κ < 10³, checked): the curve is recovered to 10⁻⁶ of its peak. The
// posterior's σ² is estimated from the residual, q(λ)/(n − 1) ≈ λ·‖c/sdev‖²/(n − 1), and with d_max ≤ σ_max(X·B)·sdev
// the posterior standard deviation of the curve is about √λ·‖c/sdev‖/σ_min(X·B) ≤ 10⁻⁷·κ·‖c‖ (equal sdevs): with
// ‖c‖ < peak/10 and κ < 10³ below 10⁻⁵ of the peak; asserted at 10⁻⁴, an order for the approximations.
TEST(AnalyticTruthBlackBox, SensitivitiesInThePriorsSpanAreRecoveredFromNoiseFreeCounts) {
  const Eigen::MatrixXd X = positive_spectra(40, 16);
  ca::SensitivityPrior prior;
  for (Eigen::Index k = 0; k < kBands; ++k) prior.wavelengths.push_back(400 + 10 * double(k));
  prior.cameras = {"constructed"};
  Eigen::MatrixXd truth(3, kBands);
  const double centre[3] = {600, 535, 460}, width[3] = {40, 45, 30};
  for (int c = 0; c < 3; ++c) {
    ca::ChannelPrior& p = prior.channels[static_cast<std::size_t>(c)];
    p.mean.resize(kBands);
    Eigen::MatrixXd raw_dirs(kBands, 3);
    for (Eigen::Index k = 0; k < kBands; ++k) {
      const double nm = prior.wavelengths[static_cast<std::size_t>(k)], u = (nm - centre[c]) / width[c];
      p.mean(k) = 0.05 + std::exp(-0.5 * u * u);  // silicon behind a dye answers a little everywhere
      raw_dirs.row(k) << u * std::exp(-0.5 * u * u), (u * u - 1) * std::exp(-0.5 * u * u), std::sin((nm - 400) / 320 * M_PI);
    }
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(raw_dirs);
    p.directions = qr.householderQ() * Eigen::MatrixXd::Identity(kBands, 3);  // orthonormal
    p.sdev = Eigen::VectorXd::Constant(3, 0.1);
    Eigen::MatrixXd B(kBands, 4);
    B.col(0) = p.mean;
    B.rightCols(3) = p.directions;
    ASSERT_LT(design_condition(X * B), 1e3) << "RGB"[c];
    const Eigen::Vector3d coeff(0.05, -0.04, 0.03);
    truth.row(c) = 1000 * (p.mean + p.directions * coeff).transpose();
    ASSERT_GT(truth.row(c).minCoeff(), 0.0) << "RGB"[c] << ": the truth must be a feasible (non-negative) curve";
  }
  const Eigen::MatrixXd raw = X * truth.transpose();
  ca::BlackBoxOptions o;
  o.prior = prior;
  const auto model = ca::fit_blackbox(X, raw, o);
  ASSERT_TRUE(model.with_prior);
  for (int c = 0; c < 3; ++c) {
    const double peak = truth.row(c).maxCoeff();
    EXPECT_LE((model.sensitivities.row(c) - truth.row(c)).cwiseAbs().maxCoeff(), 1e-6 * peak) << "RGB"[c];
    EXPECT_LE(model.sensitivity_sdev.row(c).maxCoeff(), 1e-4 * peak) << "RGB"[c];
  }
}

}  // namespace
