// The chart locator on the simulated camera's raw frames with the chart at seeded poses (rotation, tilt, distance,
// lens distortion) under several lamps: patch centres within 2 px of the simulator's geometry, per-CFA-colour
// values equal to its noiseless ground truth within the noise of the sampled mean.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "colorlab/analysis/chart_locate.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/sim/camera/camera_model.hpp"

namespace colorlab::analysis {
namespace {

namespace sim = colorlab::sim;
namespace cam = colorlab::sim::camera;

constexpr double kCentreBound = 2.0;  // px, the goal

PhotoView raw_view(const cam::RawFrame& f) {
  PhotoView v;
  v.data = f.pixels.data();
  v.width = f.width;
  v.height = f.height;
  v.channels = 1;
  v.type = SampleType::u16;
  v.bit_depth = 12;
  v.black_level = f.black_level;
  v.cfa = CfaPattern::rggb;
  return v;
}

// What the chart should look like, from the scene's own spectra (the synthetic chart is not X-Rite's layout):
// luminance per patch and the groups of patches with the same neutral spectrum.
ChartReference reference_of(const sim::Scene& scene) {
  ChartReference r;
  const auto& ps = scene.chart().patches;
  for (std::size_t k = 0; k < ps.size(); ++k) r.luminance.push_back(scene.patch_xyz(static_cast<int>(k))[1]);
  std::vector<bool> used(ps.size(), false);
  for (std::size_t a = 0; a < ps.size(); ++a) {
    if (used[a]) continue;
    std::vector<int> g{static_cast<int>(a)};
    for (std::size_t b = a + 1; b < ps.size(); ++b) {
      double d = 0;
      for (std::size_t i = 0; i < ps[a].reflectance.values.size(); ++i)
        d = std::max(d, std::abs(ps[a].reflectance.values[i] - ps[b].reflectance.values[i]));
      if (d < 0.02) g.push_back(static_cast<int>(b)), used[b] = true;
    }
    if (g.size() >= 3) r.repeated_neutrals.push_back(g);
  }
  return r;
}

struct Case {
  const char* name;
  sim::Lamp lamp;
  std::uint64_t pose_seed;  // 0: the default, square to the sensor
  bool synthetic;
};

class SimulatedPhotos : public ::testing::TestWithParam<Case> {};

TEST_P(SimulatedPhotos, PatchesWhereTheSimulatorPutThem) {
  const Case& c = GetParam();
  sim::SceneConfig sc;
  sc.seed = 4;
  sc.force_synthetic_chart = c.synthetic;
  sc.lamps_on_at_start = {c.lamp};
  auto scene = std::make_shared<sim::Scene>(sc, std::make_shared<sim::SimClock>());
  cam::CameraConfig cc;
  cc.width = 1752;
  cc.height = 1168;
  cc.chart_height_fraction = 0.62;
  if (c.pose_seed) cc.pose = cam::random_chart_pose(c.pose_seed);
  const cam::CameraModel camera(scene, cc);
  cam::CameraSettings settings;
  settings.shutter_s = c.lamp == sim::Lamp::a ? 1.0 / 60 : 1.0 / 30;
  const cam::RawFrame frame = camera.render(settings, 1);
  const auto truth = camera.ground_truth(settings);

  LocateOptions o;
  o.reference = reference_of(*scene);
  if (c.pose_seed) {
    const auto l = camera.lens();
    o.lens = LensCalibration{l.fx, l.fy, l.cx, l.cy, l.k1, l.k2, 0, 0, 0};
  }
  const ChartLocation loc = locate_chart(raw_view(frame), ChartType::sg140, o);
  EXPECT_EQ(loc.rotation_deg, 0);
  EXPECT_TRUE(loc.check.passed) << loc.check.detail;
  double worst = 0, worst_sigmas = 0;
  std::vector<bool> dusty(140, false);
  for (const auto& d : camera.dust()) dusty[static_cast<std::size_t>(d.patch)] = true;
  for (int k = 0; k < 140; ++k) {
    const auto& p = loc.patches[static_cast<std::size_t>(k)];
    const auto t = camera.patch_centre_px(k);
    const double d = std::hypot(p.centre.x - t[0], p.centre.y - t[1]);
    worst = std::max(worst, d);
    EXPECT_LE(d, kCentreBound) << c.name << " patch " << p.id;
    if (dusty[static_cast<std::size_t>(k)]) continue;  // the truth leaves dust out; a dust shadow's soft rim does not
    for (std::size_t ch = 0; ch < 3; ++ch) {
      const double want = truth[static_cast<std::size_t>(k)][ch];
      // σ of one pixel: temporal noise plus PRNU; of the mean: over the pixels used; 5σ, plus half a count.
      const double signal = want - frame.black_level;
      const double sigma = std::hypot(camera.temporal_sigma_dn(signal, settings), cc.prnu_sigma * signal);
      const double bound = 5 * sigma / std::sqrt(double(p.value[ch].used)) + 0.5;
      const double err = std::abs(p.value[ch].value - want);
      worst_sigmas = std::max(worst_sigmas, err / bound);
      EXPECT_LE(err, bound) << c.name << " patch " << p.id << " channel " << ch;
    }
  }
  std::printf("[ %s ] worst centre error %.2f px, worst value error %.2f of its bound, confidence %.2f, rms %.2f px, neutrals %.2f %%\n",
              c.name, worst, worst_sigmas, loc.confidence, loc.reprojection_rms_px, loc.check.worst_disagreement * 100);
}

INSTANTIATE_TEST_SUITE_P(Poses, SimulatedPhotos,
                         ::testing::Values(Case{"square_d65", sim::Lamp::d65, 0, true}, Case{"pose1_d65", sim::Lamp::d65, 1, true},
                                           Case{"pose2_a", sim::Lamp::a, 2, true}, Case{"pose3_tl84", sim::Lamp::tl84, 3, true},
                                           Case{"pose4_d65_xrite", sim::Lamp::d65, 4, false}),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace colorlab::analysis
