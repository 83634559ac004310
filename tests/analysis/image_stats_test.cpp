// Image statistics against direct (two-pass, all-frames-in-memory) computations on synthetic frames.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "colorlab/analysis/frame_accumulator.hpp"
#include "colorlab/analysis/patch_stats.hpp"
#include "colorlab/core/error.hpp"

namespace ca = colorlab::analysis;

namespace {

TEST(AnalysisFrameAccumulator, StreamingMeanAndStdEqualTwoPassOverAllFrames) {
  const std::size_t w = 13, h = 11, n = 7;
  std::mt19937 rng(1);
  std::uniform_int_distribution<int> u(0, 65535);
  std::vector<std::vector<std::uint16_t>> frames(n, std::vector<std::uint16_t>(w * h));
  ca::FrameAccumulator acc(w, h);
  for (auto& f : frames) {
    for (auto& v : f) v = static_cast<std::uint16_t>(u(rng));
    acc.add(f);
  }
  EXPECT_EQ(acc.frames(), n);
  auto mean = acc.mean(), sd = acc.stddev();
  for (std::size_t p = 0; p < w * h; ++p) {
    double m = 0;
    for (auto& f : frames) m += f[p];
    m /= n;
    double ss = 0;
    for (auto& f : frames) ss += (f[p] - m) * (f[p] - m);
    EXPECT_NEAR(mean[p], m, 1e-3 + 1e-6 * m);
    EXPECT_NEAR(sd[p], std::sqrt(ss / (n - 1)), 1e-2);
  }
  // Identical full-scale frames: zero variance, no overflow.
  ca::FrameAccumulator sat(2, 2);
  std::vector<std::uint16_t> full(4, 65535);
  for (int i = 0; i < 300; ++i) sat.add(full);
  EXPECT_FLOAT_EQ(sat.mean()[0], 65535.0f);
  EXPECT_FLOAT_EQ(sat.stddev()[3], 0.0f);
  EXPECT_THROW(sat.add(std::vector<std::uint16_t>(5)), colorlab::Error);
}

struct Img {
  std::size_t w, h;
  std::vector<float> px;
  ca::ImageView view() const { return {px.data(), w, h, w}; }
};

TEST(AnalysisRobustPatch, MedianThenMeanWithinKIgnoresOutliers) {
  Img img{20, 20, std::vector<float>(400)};
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(-2, 2);
  double inlier_sum = 0;
  int inliers = 0;
  for (std::size_t i = 0; i < img.px.size(); ++i) {
    if (i % 37 == 0) {
      img.px[i] = 255;  // dust, specular glints
    } else {
      img.px[i] = 100 + u(rng);
      inlier_sum += img.px[i];
      ++inliers;
    }
  }
  auto pv = ca::robust_patch_value(img.view(), {0, 0, 20, 20});
  EXPECT_NEAR(pv.value, inlier_sum / inliers, 1e-4);
  EXPECT_EQ(pv.used, static_cast<std::size_t>(inliers));
  EXPECT_EQ(pv.total, 400u);
  std::vector<double> all(img.px.begin(), img.px.end());
  EXPECT_GT(ca::summarize(all).mean - pv.value, 3.0);  // the plain mean is pulled up by the outliers
  // k scales with bit depth: 5 at 8 bit, 80 at 12 bit, 1280 at 16 bit.
  EXPECT_DOUBLE_EQ((ca::RobustOptions{12, {}}.effective_k()), 80);
  EXPECT_DOUBLE_EQ((ca::RobustOptions{16, {}}.effective_k()), 1280);
  EXPECT_DOUBLE_EQ((ca::RobustOptions{8, 2.5}.effective_k()), 2.5);
}

TEST(AnalysisRobustPatch, DefectMapFromDarkAndFlatIsExcluded) {
  const std::size_t w = 32, h = 32;
  Img dark{w, h, std::vector<float>(w * h)}, flat{w, h, std::vector<float>(w * h)}, scene{w, h, std::vector<float>(w * h)};
  std::mt19937 rng(3);
  std::normal_distribution<float> nd(0, 1);
  for (std::size_t i = 0; i < w * h; ++i) {
    dark.px[i] = 64 + nd(rng);
    flat.px[i] = 3000 + 10 * nd(rng);
    scene.px[i] = 500 + nd(rng);
  }
  const std::size_t hot = 5 * w + 7, dead = 20 * w + 9, stuck = 3 * w + 30;
  dark.px[hot] = 900;
  flat.px[dead] = 40;
  flat.px[stuck] = 16000;
  scene.px[hot] = 502;  // inside ±k: only the map can remove it
  scene.px[dead] = 498;
  auto mask = ca::defect_map(dark.view(), flat.view());
  EXPECT_EQ(mask.count(), 3u);
  EXPECT_TRUE(mask.is_bad(7, 5));
  EXPECT_TRUE(mask.is_bad(9, 20));
  EXPECT_TRUE(mask.is_bad(30, 3));
  auto with = ca::robust_patch_value(scene.view(), {0, 0, w, h}, {}, &mask);
  EXPECT_EQ(with.good, w * h - 3);
  // Independent: the same statistic over an image without those pixels at all.
  double sum = 0;
  std::size_t n = 0;
  std::vector<double> good;
  for (std::size_t i = 0; i < w * h; ++i)
    if (i != hot && i != dead && i != stuck) good.push_back(scene.px[i]);
  std::sort(good.begin(), good.end());
  const std::size_t k = good.size();
  const double med = k % 2 ? good[k / 2] : (good[k / 2 - 1] + good[k / 2]) / 2;
  for (double v : good)
    if (std::abs(v - med) <= 5) sum += v, ++n;
  EXPECT_NEAR(with.value, sum / static_cast<double>(n), 1e-4);
  EXPECT_NEAR(with.median, med, 1e-5);
}

TEST(AnalysisRobustPatch, BayerChannelsSeparated) {
  const std::size_t w = 16, h = 16;
  Img raw{w, h, std::vector<float>(w * h)};
  for (std::size_t y = 0; y < h; ++y)
    for (std::size_t x = 0; x < w; ++x) raw.px[y * w + x] = (y % 2 == 0) ? (x % 2 == 0 ? 1000.f : 2000.f) : (x % 2 == 0 ? 2000.f : 500.f);
  auto rggb = ca::cfa_patch_values(raw.view(), {2, 2, 8, 8}, ca::CfaPattern::rggb);
  EXPECT_FLOAT_EQ(rggb[0].value, 1000);
  EXPECT_FLOAT_EQ(rggb[1].value, 2000);
  EXPECT_FLOAT_EQ(rggb[2].value, 500);
  EXPECT_EQ(rggb[1].total, 32u);
  auto bggr = ca::cfa_patch_values(raw.view(), {2, 2, 8, 8}, ca::CfaPattern::bggr);
  EXPECT_FLOAT_EQ(bggr[0].value, 500);
  EXPECT_FLOAT_EQ(bggr[2].value, 1000);
}

// Its 8 % is a tolerance, not a bound: the chi-square bounds and the exact (Hadamard) case are in
// AnalyticTruthAveraging.* (analytic_truth_test.cpp).
TEST(AnalysisNoiseVsAveraging, Table2LayoutFallsAsOneOverRootN) {
  const std::size_t w = 60, h = 40, frames = 25;
  const float sigma = 2.0f;
  std::mt19937 rng(4);
  std::normal_distribution<float> nd(0, sigma);
  std::vector<Img> imgs;
  for (std::size_t f = 0; f < frames; ++f) {
    Img im{w, h, std::vector<float>(w * h)};
    for (std::size_t y = 0; y < h; ++y)
      for (std::size_t x = 0; x < w; ++x) im.px[y * w + x] = (x < 30 ? 80.f : 200.f) + nd(rng);
    imgs.push_back(std::move(im));
  }
  std::vector<ca::ImageView> views;
  for (auto& im : imgs) views.push_back(im.view());
  std::vector<ca::Rect> patches{{2, 2, 26, 36}, {32, 2, 26, 36}};
  auto rows = ca::noise_vs_averaging(views, patches);
  ASSERT_EQ(rows.size(), 6u);
  for (const auto& r : rows) {
    const double expected = sigma / std::sqrt(static_cast<double>(r.frames));
    EXPECT_NEAR(r.summary.median, expected, 0.08 * expected) << r.frames << " frames";
    EXPECT_EQ(r.patch_stdev.size(), 2u);
  }
  EXPECT_THROW(ca::noise_vs_averaging(std::span<const ca::ImageView>(views.data(), 3), patches), colorlab::Error);
}

}  // namespace
