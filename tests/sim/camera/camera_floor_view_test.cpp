// The floor view (issue 11, the camera as an imaging luminance meter): the camera aimed at the empty cabinet floor sees
// the scene's one luminance field — the LS-110's — through the floor view's perspective, its lens's cos⁴ fall-off and
// vignetting; aiming it back at the chart gives the chart's frames again, bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "camera_fixture.hpp"

namespace colorlab::sim::camera {
namespace {

constexpr int kFrames = 16;

struct Window {
  double mean = 0;
  int pixels = 0;
};

// Mean of the green pixels of the averaged frame in a (2h+1)² window around a pixel centre.
Window green_window(const std::vector<double>& avg, int width, double cx, double cy, int h) {
  Window w;
  double sum = 0;
  for (int y = int(std::lround(cy)) - h; y <= int(std::lround(cy)) + h; ++y)
    for (int x = int(std::lround(cx)) - h; x <= int(std::lround(cx)) + h; ++x) {
      if (rggb_channel(x, y) != 1) continue;
      sum += avg[static_cast<std::size_t>(y) * width + x] - 256.0;
      ++w.pixels;
    }
  w.mean = sum / w.pixels;
  return w;
}

TEST(SimFloorView, TheFloorIsTheMetersFieldThroughTheLensFallOff) {
  auto scene = test::d65_scene(5);
  CameraModel cam(scene, test::small_camera());
  const CameraSettings s;  // f/4, 1/30 s, ISO 100
  const RawFrame chart_before = cam.render(s, 0);
  cam.set_view(CameraModel::View::floor);
  ASSERT_EQ(cam.view(), CameraModel::View::floor);

  std::vector<double> avg(static_cast<std::size_t>(cam.width() * cam.height()), 0.0);
  RawFrame f;
  for (int k = 0; k < kFrames; ++k) {
    cam.render_into(f, s, static_cast<std::uint64_t>(k));
    for (std::size_t p = 0; p < avg.size(); ++p) avg[p] += f.pixels[p] / double(kFrames);
  }

  // signal / (true luminance × relative illumination) is one constant over the floor: the camera sees the field the
  // meter reads, dimmed only by the optics the truth names.
  std::vector<double> ratio, sigma;
  double lowest = 1, highest = 0;
  const auto& cfg = cam.config();
  for (int r = 0; r < floor_rows; ++r)
    for (int c = 0; c < floor_cols; ++c) {
      const auto [x, y] = Scene::floor_spot_position_mm(r, c);
      const auto px = cam.floor_point_px(x, y);
      const double ri = cam.relative_illumination(px[0], px[1], s.f_number, CameraModel::View::floor);
      lowest = std::min(lowest, ri), highest = std::max(highest, ri);
      const Window w = green_window(avg, cam.width(), px[0], px[1], 2);
      ratio.push_back(w.mean / (scene->floor_luminance(r, c) * ri));
      // The window mean's σ from the noise model: temporal (shot, read, ADC) over N frames and the pixels' PRNU, over
      // its pixels; the DSNU and column offsets (≤ 0.6 DN, also averaged) are an order below at these signals.
      const double t = cam.temporal_sigma_dn(w.mean, s);
      sigma.push_back(std::sqrt(t * t / kFrames + std::pow(cfg.prnu_sigma * w.mean, 2) + 0.36) / std::sqrt(double(w.pixels)) / w.mean);
    }
  // The fall-off is what makes a calibration on a few spots a flat-field problem: a third of the light lost at the
  // floor's front corners, none on the axis.
  EXPECT_LT(lowest, 0.75);
  EXPECT_GT(highest, 0.97);
  double mean = 0;
  for (double v : ratio) mean += v / double(ratio.size());
  for (std::size_t i = 0; i < ratio.size(); ++i) {
    // 5σ of the noise, and 0.05 % for the field's bilinear interpolation between the renderer's 16-pixel nodes (the
    // field's curvature, at most 0.9/600² per mm² relative, over a node cell of ≤ 30 mm: h²/8 · f'' ≈ 0.01 %), and for
    // a dust speck's edge (none lies on a spot here: the test would see its 15 % and fail loudly).
    EXPECT_NEAR(ratio[i] / mean, 1.0, 5 * sigma[i] + 5e-4) << "spot row " << i / floor_cols << " col " << i % floor_cols;
  }

  cam.set_view(CameraModel::View::chart);
  const RawFrame chart_after = cam.render(s, 0);
  EXPECT_EQ(chart_before.pixels, chart_after.pixels);
}

TEST(SimFloorView, CornersAreTheFloorsAndTheMapIsAHomography) {
  CameraModel cam(test::d65_scene(), test::small_camera(640, 428));
  const auto c = cam.floor_corners_px();
  // Front edge nearer than the back: wider, lower in the frame, symmetric about the vertical centre line.
  EXPECT_GT(c[1][0] - c[0][0], c[2][0] - c[3][0]);
  EXPECT_GT(c[0][1], c[3][1]);
  EXPECT_NEAR(c[0][0] + c[1][0], cam.width() - 1.0, 1e-9);
  EXPECT_NEAR(c[0][1], c[1][1], 1e-9);
  // The front edge spans 94 % of the width (the floor view's framing).
  EXPECT_NEAR((c[1][0] - c[0][0]) / cam.width(), 0.94, 1e-9);
  // A floor point's image lies on the line between the corners' images where a homography puts it: the middle of
  // the front edge is halfway between the front corners.
  const auto mid = cam.floor_point_px(cabinet_width_mm / 2, 0);
  EXPECT_NEAR(mid[0], (c[0][0] + c[1][0]) / 2, 1e-9);
}

}  // namespace
}  // namespace colorlab::sim::camera
