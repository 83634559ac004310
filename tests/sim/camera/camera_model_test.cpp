// Image formation: geometry, determinism, exposure, defects, dust, vignetting, clipping.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "camera_fixture.hpp"
#include "colorlab/core/data_paths.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::sim::camera {
namespace {

// Mean of one CFA channel over a patch, ignoring the dust specks' pixels (they are outliers by design).
double patch_channel_mean(const RawFrame& f, const CameraModel& cam, int patch, int channel) {
  const auto r = cam.patch_region(patch);
  double sum = 0;
  int n = 0;
  for (int y = r.y; y < r.y + r.height; ++y)
    for (int x = r.x; x < r.x + r.width; ++x) {
      if (rggb_channel(x, y) != channel) continue;
      bool dusty = false;
      for (const auto& d : cam.dust())
        dusty |= std::hypot(x + 0.5 - d.x, y + 0.5 - d.y) < d.radius + 1;
      bool defect = false;
      for (const auto& d : cam.defects()) defect |= d.x == x && d.y == y;
      if (dusty || defect) continue;
      sum += f.at(x, y);
      ++n;
    }
  return sum / n;
}

TEST(SimCameraModel, SameSeedAndFrameGiveTheSameBytesWhateverTheThreadCount) {
  auto scene = test::d65_scene();
  CameraConfig one = test::small_camera();
  one.threads = 1;
  CameraConfig two = test::small_camera();
  two.threads = 2;
  const CameraModel a(scene, one), b(scene, two);
  const CameraSettings s;
  const RawFrame fa = a.render(s, 7), fb = b.render(s, 7);
  EXPECT_EQ(fa.pixels, fb.pixels);
  EXPECT_EQ(fa.frame_index, 7u);
  EXPECT_NE(a.render(s, 8).pixels, fa.pixels);
  // A different scene seed is a different camera (defects, dust, noise).
  const CameraModel c(test::d65_scene(2), one);
  EXPECT_NE(c.render(s, 7).pixels, fa.pixels);
}

TEST(SimCameraModel, FrameLayoutIsA12BitRggbMosaic) {
  const CameraModel cam(test::d65_scene(), test::small_camera());
  const RawFrame f = cam.render({}, 0);
  EXPECT_EQ(f.width, 700);
  EXPECT_EQ(f.height, 468);
  EXPECT_EQ(f.pixels.size(), 700u * 468u);
  EXPECT_EQ(f.cfa, "RGGB");
  EXPECT_EQ(f.black_level, 256);
  EXPECT_EQ(*std::max_element(f.pixels.begin(), f.pixels.end()) <= 4095, true);
  // On a red patch (synthetic chart: pick the patch with the largest R/B truth) R pixels outshine B pixels.
  const auto truth = cam.ground_truth(CameraSettings{});
  int red = 0;
  for (int i = 0; i < chart_patch_count; ++i)
    if ((truth[i][0] - 256) / (truth[i][2] - 256 + 1) > (truth[red][0] - 256) / (truth[red][2] - 256 + 1)) red = i;
  EXPECT_GT(patch_channel_mean(f, cam, red, 0), patch_channel_mean(f, cam, red, 2) + 100);
}

TEST(SimCameraModel, RenderedMeansMatchTheGroundTruth) {
  const CameraModel cam(test::d65_scene(), test::small_camera());
  const CameraSettings s;
  const auto truth = cam.ground_truth(s);
  // Average 8 frames, then compare every patch and channel with its truth within 5 σ of the averaged noise
  // plus the PRNU that does not average out (0.6 % / √pixels).
  std::vector<double> acc(static_cast<std::size_t>(cam.width() * cam.height()), 0.0);
  RawFrame f;
  const int frames = 8;
  for (int i = 0; i < frames; ++i) {
    cam.render_into(f, s, static_cast<std::uint64_t>(i));
    for (std::size_t p = 0; p < acc.size(); ++p) acc[p] += f.pixels[p];
  }
  RawFrame mean = f;
  for (std::size_t p = 0; p < acc.size(); ++p) mean.pixels[p] = static_cast<std::uint16_t>(std::lround(acc[p] / frames));
  int checked = 0;
  for (int i = 0; i < chart_patch_count; ++i)
    for (int c = 0; c < 3; ++c) {
      const auto r = cam.patch_region(i);
      const double n = r.width * r.height / (c == 1 ? 2.0 : 4.0);
      const double signal = truth[i][c] - 256;
      const double tol = 5 * cam.temporal_sigma_dn(signal, s) / std::sqrt(n * frames) + 5 * 0.006 * signal / std::sqrt(n) + 0.6;
      EXPECT_NEAR(patch_channel_mean(mean, cam, i, c), truth[i][c], tol) << "patch " << i << " channel " << c;
      ++checked;
    }
  EXPECT_EQ(checked, 420);
  // A bright white border patch is well exposed but not clipped at f/4, 1/30 s, ISO 100 (Table 7). This one assertion
  // checks the simulator's tuning to the dissertation; the test is otherwise held to the ground truth, so not labelled.
  const int a1 = 0;  // A1: a white border patch
  EXPECT_GT(truth[a1][1], 1500);
  EXPECT_LT(truth[a1][1], 4000);
}

TEST(SimCameraModel, ExposureScalesWithShutterApertureAndIso) {
  const CameraModel cam(test::d65_scene(), test::small_camera());
  const int patch = 44;  // an inner patch
  const double base = cam.ground_truth(patch, {4.0, 1 / 30.0, 100})[1] - 256;
  EXPECT_NEAR(cam.ground_truth(patch, {4.0, 1 / 60.0, 100})[1] - 256, base / 2, 0.01 * base);
  EXPECT_NEAR(cam.ground_truth(patch, {4.0, 1 / 60.0, 200})[1] - 256, base, 0.01 * base);
  // One stop of aperture: half the light, slightly changed by vignetting (which eases as the lens stops down).
  EXPECT_NEAR(cam.ground_truth(patch, {5.6568542, 1 / 30.0, 100})[1] - 256, base / 2, 0.03 * base);
  EXPECT_THROW(cam.render({0.0, 1 / 30.0, 100}, 0), Error);
  EXPECT_THROW(cam.render({4.0, -1, 100}, 0), Error);
  EXPECT_THROW(cam.render({4.0, 1 / 30.0, 25}, 0), Error);
  EXPECT_THROW(cam.patch_region(140), Error);
}

// Tuning: checks the simulator's tuning to the dissertation (Table 7), not the analysis; the analysis is checked by
// AnalyticTruthUniformity.DimmerProportionalityIsExactForProportionalLightAndMeasuresAShortfall.
TEST(SimCameraModel, DimmerAndExposureCompensationAreNotQuiteEquivalent) {
  // Table 7: halving the light and doubling the exposure should give the same image "theoretically".
  auto scene = test::d65_scene();
  const CameraModel cam(scene, test::small_camera());
  const double full = cam.ground_truth(44, {4.0, 1 / 30.0, 100})[1] - 256;
  scene->set_dimmer(50);
  const double half = cam.ground_truth(44, {4.0, 1 / 15.0, 100})[1] - 256;
  EXPECT_NEAR(half / full, 2 * Scene::dimmer_output(50), 0.01);
  EXPECT_LT(half, full * 0.95);
  scene->set_lamp(Lamp::d65, false);
  EXPECT_NEAR(cam.ground_truth(44, {4.0, 1 / 30.0, 100})[1], 256, 0.1);  // only dark current left
}

TEST(SimCameraModel, HotAndDeadPixelsAreFixedPerCamera) {
  const CameraModel cam(test::d65_scene(), test::small_camera());
  const CameraModel same(test::d65_scene(), test::small_camera());
  ASSERT_FALSE(cam.defects().empty());
  const RawFrame f = cam.render({}, 3);
  int hot = 0, dead = 0;
  for (const auto& d : cam.defects()) {
    if (d.kind == PixelDefect::Kind::hot) {
      EXPECT_GT(f.at(d.x, d.y), 256 + 250);
      ++hot;
    } else {
      EXPECT_NEAR(f.at(d.x, d.y), 256, 10);
      ++dead;
    }
  }
  EXPECT_GT(hot, 0);
  EXPECT_GT(dead, 0);
  ASSERT_EQ(same.defects().size(), cam.defects().size());
  for (std::size_t i = 0; i < cam.defects().size(); ++i) EXPECT_EQ(same.defects()[i].x, cam.defects()[i].x);
}

TEST(SimCameraModel, DustSpecksDarkenPatchPixelsLikeFig31c) {
  const CameraModel cam(test::d65_scene(), test::small_camera());
  ASSERT_EQ(cam.dust().size(), 6u);
  const RawFrame f = cam.render({}, 0);
  const auto truth = cam.ground_truth(CameraSettings{});
  for (const auto& d : cam.dust()) {
    const auto r = cam.patch_region(d.patch);
    EXPECT_GE(d.x, r.x);
    EXPECT_LE(d.x, r.x + r.width);
    const int x = static_cast<int>(d.x), y = static_cast<int>(d.y);
    const double expected = truth[d.patch][rggb_channel(x, y)] - 256;
    const double got = f.at(x, y) - 256;
    // Centre of the shadow: transmission 0.55–0.85 of the signal, beyond noise for any patch brighter than ~100 DN.
    if (expected > 300) {
      EXPECT_LT(got, expected * 0.92) << "speck on patch " << d.patch;
    }
  }
}

TEST(SimCameraModel, VignettingDarkensCornersMoreWideOpen) {
  const CameraModel cam(test::d65_scene(), test::small_camera());
  // A1 (corner of the chart) relative to F5 (centre) at f/2.8 and f/11, exposure-compensated: the lamp field
  // is the same, only the lens differs.
  const int corner = 0, centre = 5 * chart_rows + 4;
  auto ratio = [&](double f) {
    const CameraSettings s{f, 1 / 30.0 * (f / 4) * (f / 4), 100};
    const auto t = cam.ground_truth(s);
    return (t[corner][1] - 256) / (t[centre][1] - 256);
  };
  EXPECT_LT(ratio(2.8), ratio(11.0) * 0.985);
}

TEST(SimCameraModel, LongExposuresClipAt12Bits) {
  const CameraModel cam(test::d65_scene(), test::small_camera());
  const RawFrame f = cam.render({4.0, 1.0, 100}, 0);
  const auto clipped = std::count(f.pixels.begin(), f.pixels.end(), std::uint16_t{4095});
  EXPECT_GT(clipped, static_cast<long>(f.pixels.size() / 4));
  EXPECT_EQ(*std::max_element(f.pixels.begin(), f.pixels.end()), 4095);
}

TEST(SimCameraModel, SensitivitiesComeFromTheCanon20dFileOrTheParametricDefault) {
  auto scene = test::d65_scene();
  CameraConfig param = test::small_camera();
  param.force_parametric_sensitivities = true;
  const CameraModel p(scene, param);
  EXPECT_EQ(p.sensitivity_source(), "parametric");
  // Peaks where Bayer dyes put them.
  auto peak = [](const Spectrum& s) {
    return s.wavelength(static_cast<std::size_t>(std::max_element(s.values.begin(), s.values.end()) - s.values.begin()));
  };
  EXPECT_NEAR(peak(p.sensitivities()[0]), 600, 15);
  EXPECT_NEAR(peak(p.sensitivities()[1]), 535, 15);
  EXPECT_NEAR(peak(p.sensitivities()[2]), 460, 15);
  if (!paths::shared_data_file("camera_ssf_canon_eos_20d_camspec_10nm_400_720.csv"))
    GTEST_SKIP() << "shared data set absent: Canon 20D curves not available";
  const CameraModel c(scene, test::small_camera());
  EXPECT_NE(c.sensitivity_source().find("canon_eos_20d"), std::string::npos);
  EXPECT_EQ(c.sensitivities()[1].at(390), 0.0);  // blind outside the measured 400–720 nm
  EXPECT_GT(peak(c.sensitivities()[1]), 500);
  EXPECT_LT(peak(c.sensitivities()[1]), 560);
}

TEST(SimCameraModel, ColorMatrixMapsD65WhiteToTheCameraNeutral) {
  const CameraModel cam(test::d65_scene(), test::small_camera());
  const auto m = cam.xyz_to_camera_d65();
  const double white[3] = {0.95047, 1.0, 1.08883};  // D65, Y = 1
  const auto neutral = cam.as_shot_neutral();
  double cam_white[3];
  for (int r = 0; r < 3; ++r) cam_white[r] = m[r * 3] * white[0] + m[r * 3 + 1] * white[1] + m[r * 3 + 2] * white[2];
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(cam_white[c] / cam_white[1], neutral[c], 0.03) << c;
  EXPECT_DOUBLE_EQ(neutral[1], 1.0);
}

}  // namespace
}  // namespace colorlab::sim::camera

namespace colorlab::sim::camera {
namespace {

TEST(SimCameraModel, FramesDuringWarmUpAreDarker) {
  SceneConfig cfg;
  cfg.force_synthetic_chart = true;
  cfg.warmup_tau_s = 1e6;  // effectively frozen at its start value for the duration of the test
  auto scene = std::make_shared<Scene>(cfg, std::make_shared<SimClock>());
  const CameraModel cam(scene, test::small_camera());
  scene->set_lamp(Lamp::d65, true);
  const double cold = cam.ground_truth(44, {})[1] - 256;
  const RawFrame f = cam.render({}, 0);
  SceneConfig warm_cfg = cfg;
  warm_cfg.lamps_on_at_start = {Lamp::d65};
  const CameraModel warm_cam(std::make_shared<Scene>(warm_cfg, std::make_shared<SimClock>()), test::small_camera());
  const double warm = warm_cam.ground_truth(44, {})[1] - 256;
  EXPECT_NEAR(cold / warm, cfg.warmup_start_fraction, 0.002);
  // The rendered frame follows the same (cold) truth.
  const auto r = cam.patch_region(44);
  double sum = 0;
  int n = 0;
  for (int y = r.y; y < r.y + r.height; ++y)
    for (int x = r.x; x < r.x + r.width; ++x)
      if (rggb_channel(x, y) == 1) sum += f.at(x, y) - 256, ++n;
  EXPECT_NEAR(sum / n, cold, 0.03 * cold);
}

}  // namespace
}  // namespace colorlab::sim::camera
