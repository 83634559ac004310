// The operator placing the chart (place_chart, the lens-calibration campaign's poses): the chart moves in the frame,
// the lens does not, and putting it back restores the configured geometry bit for bit.
#include <gtest/gtest.h>

#include <cmath>

#include "camera_fixture.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::sim::camera {
namespace {

CameraConfig posed_camera() {
  CameraConfig c = test::small_camera();
  ChartPose p;
  p.distance_mm = 900, p.tilt_deg = 5, p.k1 = -0.08, p.k2 = 0.03;
  c.pose = p;
  return c;
}

void expect_same_lens(const LensIntrinsics& a, const LensIntrinsics& b) {
  EXPECT_NEAR(a.fx, b.fx, 1e-9 * b.fx);
  EXPECT_NEAR(a.fy, b.fy, 1e-9 * b.fy);
  EXPECT_DOUBLE_EQ(a.cx, b.cx);
  EXPECT_DOUBLE_EQ(a.cy, b.cy);
  EXPECT_DOUBLE_EQ(a.k1, b.k1);
  EXPECT_DOUBLE_EQ(a.k2, b.k2);
}

TEST(SimChartPlacement, TheChartMovesTheLensStaysAndPuttingItBackRestoresTheConfiguredGeometry) {
  CameraModel cam(test::d65_scene(), posed_camera());
  const LensIntrinsics lens = cam.lens();
  const auto centre = cam.patch_centre_px(0);
  const auto region = cam.patch_region(70);
  const RawFrame before = cam.render({}, 3);
  EXPECT_FALSE(cam.chart_placement().has_value());

  ChartPlacement q;
  q.tilt_deg = 20, q.swing_deg = -10, q.rotation_deg = 3, q.fill = 0.5, q.shift_x = -0.15, q.shift_y = 0.1;
  cam.place_chart(q);
  expect_same_lens(cam.lens(), lens);
  ASSERT_TRUE(cam.chart_placement().has_value());
  EXPECT_EQ(cam.chart_placement()->tilt_deg, 20);
  // Pushed left and down, and smaller (0.5 of the height instead of 0.8).
  const auto corners = cam.patch_grid_corners_px();
  const double middle_x = (corners[0][0] + corners[1][0] + corners[2][0] + corners[3][0]) / 4;
  const double middle_y = (corners[0][1] + corners[1][1] + corners[2][1] + corners[3][1]) / 4;
  EXPECT_LT(middle_x, 700 / 2.0 - 0.1 * 700);
  EXPECT_GT(middle_y, 468 / 2.0 + 0.05 * 468);
  EXPECT_LT(std::abs(corners[3][1] - corners[0][1]), 0.55 * 468);
  EXPECT_NE(cam.render({}, 3).pixels, before.pixels);

  // A placement the geometry refuses leaves the chart where it was.
  ChartPlacement bad = q;
  bad.fill = 1.5;
  EXPECT_THROW(cam.place_chart(bad), Error);
  bad = q;
  bad.tilt_deg = 75;
  EXPECT_THROW(cam.place_chart(bad), Error);
  EXPECT_EQ(cam.chart_placement()->tilt_deg, 20);

  cam.place_chart(std::nullopt);
  EXPECT_FALSE(cam.chart_placement().has_value());
  expect_same_lens(cam.lens(), lens);
  EXPECT_EQ(cam.patch_centre_px(0), centre);
  EXPECT_EQ(cam.patch_region(70).x, region.x);
  EXPECT_EQ(cam.patch_region(70).width, region.width);
  EXPECT_EQ(cam.render({}, 3).pixels, before.pixels);
}

TEST(SimChartPlacement, ASquareChartPlacedIsSeenThroughTheNominalLens) {
  CameraModel cam(test::d65_scene(), test::small_camera());
  const LensIntrinsics lens = cam.lens();
  ChartPlacement q;
  q.tilt_deg = -15, q.fill = 0.6, q.shift_x = 0.1;
  cam.place_chart(q);
  expect_same_lens(cam.lens(), lens);
  cam.place_chart(std::nullopt);
  expect_same_lens(cam.lens(), lens);
}

}  // namespace
}  // namespace colorlab::sim::camera
