// Frame averaging (§6.1.3, Table 2): the per-patch pixel std falls like 1/√N until the fixed pattern
// (PRNU, offsets, the field's gradient across the patch) is all that is left.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "camera_fixture.hpp"

namespace colorlab::sim::camera {
namespace {

// Std of the G pixels inside the middle half of a patch (the dissertation's "subareas"), dust pixels excluded.
double patch_green_std(const std::vector<double>& img, int width, const CameraModel& cam, int patch) {
  const auto r = cam.patch_region(patch);
  double s = 0, s2 = 0;
  int n = 0;
  for (int y = r.y + r.height / 4; y < r.y + 3 * r.height / 4; ++y)
    for (int x = r.x + r.width / 4; x < r.x + 3 * r.width / 4; ++x) {
      if (rggb_channel(x, y) != 1) continue;
      bool dusty = false;
      for (const auto& d : cam.dust()) dusty |= std::hypot(x + 0.5 - d.x, y + 0.5 - d.y) < d.radius + 1;
      if (dusty) continue;
      const double v = img[static_cast<std::size_t>(y) * width + x];
      s += v, s2 += v * v, ++n;
    }
  const double mean = s / n;
  return std::sqrt(std::max(0.0, s2 / n - mean * mean));
}

// Tuning: checks the simulator's tuning to the dissertation (Table 2's shape), not the analysis; the analysis is
// checked by AnalyticTruthAveraging.* (analysis_analytic_truth_test).
TEST(SimFrameAveraging, NoiseFallsAsInverseRootNDownToTheFixedPatternFloor) {
  const CameraModel cam(test::d65_scene(), test::small_camera());
  const CameraSettings s;
  const std::vector<int> counts{1, 2, 4, 8, 16, 25};
  std::vector<double> sum(static_cast<std::size_t>(cam.width() * cam.height()), 0.0);
  std::vector<double> median_std;
  RawFrame f;
  int done = 0;
  for (int n : counts) {
    for (; done < n; ++done) {
      cam.render_into(f, s, static_cast<std::uint64_t>(done));
      for (std::size_t p = 0; p < sum.size(); ++p) sum[p] += f.pixels[p];
    }
    std::vector<double> avg(sum.size());
    for (std::size_t p = 0; p < sum.size(); ++p) avg[p] = sum[p] / n;
    std::vector<double> stds;
    for (int i = 0; i < chart_patch_count; ++i) stds.push_back(patch_green_std(avg, cam.width(), cam, i));
    std::nth_element(stds.begin(), stds.begin() + stds.size() / 2, stds.end());
    median_std.push_back(stds[stds.size() / 2]);
    std::printf("N=%2d median patch G std %.2f DN (ratio to N=1: %.2f; Table 2 G median ratio: %.2f)\n", n,
                median_std.back(), median_std.back() / median_std.front(),
                std::array<double, 6>{0.95, 0.77, 0.66, 0.59, 0.55, 0.54}[median_std.size() - 1] / 0.95);
  }
  // Strictly decreasing, by less and less.
  for (std::size_t i = 1; i < median_std.size(); ++i) EXPECT_LT(median_std[i], median_std[i - 1]);
  EXPECT_GT(median_std[1] - median_std[2], median_std[4] - median_std[5]);
  // Model σ²(N) = floor² + temporal²/N through N = 1 and N = 25 predicts the middle points.
  const double t2 = (median_std[0] * median_std[0] - median_std[5] * median_std[5]) / (1.0 - 1.0 / 25.0);
  const double floor2 = median_std[0] * median_std[0] - t2;
  ASSERT_GT(floor2, 0.0);
  for (std::size_t i = 1; i < 5; ++i) {
    const double predicted = std::sqrt(floor2 + t2 / counts[i]);
    EXPECT_NEAR(median_std[i], predicted, 0.08 * predicted) << "N=" << counts[i];
  }
  // Table 2's shape: 25 frames leave roughly half of the single-frame std (0.54/0.95 in G).
  const double ratio = median_std[5] / median_std[0];
  EXPECT_GT(ratio, 0.35);
  EXPECT_LT(ratio, 0.75);
}

}  // namespace
}  // namespace colorlab::sim::camera
