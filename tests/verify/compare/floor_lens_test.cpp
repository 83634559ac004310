// The light half placed through the lens calibration (issue 23, docs/verify.md "Where each spot is"): the floor
// photograph is distorted, the rendering made with the exported camera is that camera's pinhole. The truth is the
// simulator's: its floor view through a lens with radial distortion states where a floor point is photographed
// (floor_point_px, distorted) and where the same camera without the distortion sees it (floor_point_pinhole_px: the
// rendering). Spots placed from the photograph's four corners must land on the latter; a pinhole homography of the
// distorted corners misses by pixels towards the frame's edges. The undistortion itself is checked against
// OpenCV's undistortPoints, an independent implementation of the same model.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <opencv2/calib3d.hpp>
#include <vector>

#include "colorlab/core/error.hpp"
#include "colorlab/sim/camera/camera_model.hpp"
#include "colorlab/sim/scene.hpp"
#include "colorlab/verify/compare/photograph_lens.hpp"
#include "colorlab/verify/compare/scene_from_runs.hpp"

namespace colorlab::verify {
namespace {

namespace cam = colorlab::sim::camera;
using nlohmann::json;

constexpr int kWidth = 3504, kHeight = 2336;
// A wide lens's barrel distortion (the floor view spans 1.2 m from 1.6 m): ~30 px at the front corners.
constexpr double kK1 = -0.10, kK2 = 0.02;

std::unique_ptr<cam::CameraModel> floor_camera(double k1, double k2) {
  sim::SceneConfig sc;
  sc.seed = 4;
  auto scene = std::make_shared<sim::Scene>(sc, std::make_shared<sim::SimClock>());
  cam::CameraConfig cc;
  cc.width = kWidth, cc.height = kHeight;
  cc.floor_k1 = k1, cc.floor_k2 = k2;
  return std::make_unique<cam::CameraModel>(scene, cc);
}

// The floor-luminance photograph row as the campaign records it: the floor's corners measured on the photograph.
json photograph_row(const cam::CameraModel& camera) {
  json corners = json::array();
  for (const auto& c : camera.floor_corners_px()) corners.push_back({c[0], c[1]});
  return {{"width", kWidth}, {"height", kHeight}, {"corners_px", corners}, {"spot_mm", 20.0}, {"lamp", "D65"}, {"dimmer_percent", 100}};
}

PhotographLens lens_of(const cam::CameraModel& camera) {
  const auto l = camera.floor_lens();
  return {l.fx, l.fy, l.cx, l.cy, l.k1, l.k2, "the simulator's floor lens"};
}

TEST(VerifyFloorLens, UndistortionAgreesWithOpenCv) {
  const PhotographLens lens{2900.0, 2903.1, 1755.3, 1164.1, -0.12, 0.05, "test"};
  const cv::Matx33d K(lens.fx, 0, lens.cx, 0, lens.fy, lens.cy, 0, 0, 1);
  const cv::Matx<double, 1, 4> D(lens.k1, lens.k2, 0, 0);
  std::vector<cv::Point2d> pts;
  for (int y = 0; y < kHeight; y += 233)
    for (int x = 0; x < kWidth; x += 217) pts.emplace_back(x, y);
  pts.emplace_back(0, 0), pts.emplace_back(kWidth - 1, kHeight - 1), pts.emplace_back(lens.cx, lens.cy);
  std::vector<cv::Point2d> cv_out;
  cv::undistortPoints(pts, cv_out, K, D, cv::noArray(), K, cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-14));
  double worst = 0, worst_round = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const auto u = undistort_px(lens, {pts[i].x, pts[i].y});
    worst = std::max(worst, std::hypot(u[0] - cv_out[i].x, u[1] - cv_out[i].y));
    const auto back = distort_px(lens, u);
    worst_round = std::max(worst_round, std::hypot(back[0] - pts[i].x, back[1] - pts[i].y));
  }
  std::printf("[ undistort ] %zu points: %.2e px from OpenCV at most, distort(undistort) %.2e px\n", pts.size(), worst, worst_round);
  EXPECT_LT(worst, 1e-6);
  EXPECT_LT(worst_round, 1e-9);
}

TEST(VerifyFloorLens, RefusesALensWithoutFocalLengthOrBeyondItsFold) {
  const std::array<double, 2> p{100, 100};
  try {
    (void)undistort_px(PhotographLens{0, 1000, 500, 500, 0, 0, ""}, p);
    ADD_FAILURE() << "a lens without a focal length was taken";
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::bad_parameter);
  }
  // Strong barrel distortion folds back within the frame: r (1 − 2 r²) peaks at r = 0.41, rd 0.27; the corner's
  // rd ≈ 0.6 has no undistorted position.
  try {
    (void)undistort_px(PhotographLens{1000, 1000, 1000, 1000, -2.0, 0, ""}, {1600, 1000});
    ADD_FAILURE() << "a point beyond the lens model's fold was undistorted";
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::bad_data);
    EXPECT_NE(std::string(e.what()).find("one-to-one"), std::string::npos) << e.what();
  }
}

// The misplacement of every floor spot of the widest grid floor-luminance samples (8 × 20, pitch 60 × 54 mm: the
// first 10 columns are the LS-110's 80 spots), in the photograph's pixels, with and without the lens.
TEST(VerifyFloorLens, ADistortedLensNoLongerMisplacesSpotsNearTheEdges) {
  const auto camera = floor_camera(kK1, kK2);
  const json row = photograph_row(*camera);
  const FloorPlacement pinhole(row, kWidth, kHeight), calibrated(row, kWidth, kHeight, {}, lens_of(*camera));
  const FloorGeometry floor;
  double before80 = 0, after80 = 0, before = 0, after = 0;
  std::string worst_at;
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 20; ++c) {
      const double x = (c + 0.5) * floor.pitch_x_mm, y = (r + 0.5) * floor.pitch_y_mm;
      const auto truth = camera->floor_point_pinhole_px(x, y);
      const auto b = pinhole.rendering_px(x, y), a = calibrated.rendering_px(x, y);
      const double eb = std::hypot(b[0] - truth[0], b[1] - truth[1]), ea = std::hypot(a[0] - truth[0], a[1] - truth[1]);
      if (eb > before) before = eb, worst_at = "r" + std::to_string(r) + "c" + std::to_string(c);
      after = std::max(after, ea);
      if (c < 10) before80 = std::max(before80, eb), after80 = std::max(after80, ea);
    }
  std::printf("[ floor k1 %.2f k2 %.2f ] spot misplacement in the rendering (photograph px), worst: 80 LS-110 spots %.2f px "
              "pinhole -> %.2e px through the lens; 8 x 20 grid %.2f px (at %s) -> %.2e px\n",
              kK1, kK2, before80, after80, before, worst_at.c_str(), after);
  // The homography of the undistorted corners is exact for the pinhole rendering: only arithmetic remains.
  EXPECT_LT(after, 1e-6);
  // And the old placement was measurably wrong here (or this test could not tell the two apart).
  EXPECT_GT(before, 2.0);

  // A rendering at half the photograph's size: the same places, scaled (pixel centres at integers on both sides).
  const FloorPlacement half(row, kWidth / 2, kHeight / 2, {}, lens_of(*camera));
  const auto t = camera->floor_point_pinhole_px(30, 27);
  const auto h = half.rendering_px(30, 27);
  EXPECT_NEAR(h[0], (t[0] + 0.5) / 2 - 0.5, 1e-6);
  EXPECT_NEAR(h[1], (t[1] + 0.5) / 2 - 0.5, 1e-6);

  // Without distortion the lens changes nothing: the pinhole path is what it was.
  const auto flat = floor_camera(0, 0);
  const json flat_row = photograph_row(*flat);
  const FloorPlacement p0(flat_row, kWidth, kHeight), p1(flat_row, kWidth, kHeight, {}, lens_of(*flat));
  const auto q0 = p0.rendering_px(570, 405), q1 = p1.rendering_px(570, 405), qt = flat->floor_point_pinhole_px(570, 405);
  EXPECT_EQ(q0, q1);
  EXPECT_NEAR(q0[0], qt[0], 1e-6);
  EXPECT_NEAR(q0[1], qt[1], 1e-6);
}

// Through scene_from_runs, as `colorlab verify` builds the light half: each floor cell's sampled square is centred
// on the truth (to the half pixel an integer square allows) with the lens, not without it.
TEST(VerifyFloorLens, SceneFromRunsPlacesTheCellsThroughTheLens) {
  const auto camera = floor_camera(kK1, kK2);
  json rows = json::array();
  json photo = photograph_row(*camera);
  photo["calibration"] = {{{"residual_pct", 1.0}}, {{"residual_pct", -1.0}}};  // the flat field's, as the campaign stores it
  rows.push_back({{"step", "P/D65/D100"}, {"quantity", "floor_photograph"}, {"data", photo}});
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 20; ++c)
      rows.push_back({{"step", "F/D65/D100/r" + std::to_string(r) + "c" + std::to_string(c)}, {"value", 100.0}});
  const json run{{"id", "floor"}, {"campaign", "floor-luminance"}, {"measurements", rows}};
  RunsSceneOptions with;
  with.lens = lens_of(*camera);
  const MeasuredScene a = scene_from_runs({run}, kWidth, kHeight, with), b = scene_from_runs({run}, kWidth, kHeight);
  ASSERT_EQ(a.floor.size(), 160u);
  ASSERT_EQ(b.floor.size(), 160u);
  double worst_a = 0, worst_b = 0;
  const FloorGeometry floor;
  for (std::size_t i = 0; i < a.floor.size(); ++i) {
    const auto& cell = a.floor[i];
    const auto truth = camera->floor_point_pinhole_px((cell.col + 0.5) * floor.pitch_x_mm, (cell.row + 0.5) * floor.pitch_y_mm);
    const auto centre = [](const PixelRect& p) { return std::array<double, 2>{p.x + (p.w - 1) / 2.0, p.y + (p.h - 1) / 2.0}; };
    const auto ca = centre(cell.rendering_region), cb = centre(b.floor[i].rendering_region);
    worst_a = std::max({worst_a, std::abs(ca[0] - truth[0]), std::abs(ca[1] - truth[1])});
    worst_b = std::max({worst_b, std::abs(cb[0] - truth[0]), std::abs(cb[1] - truth[1])});
  }
  std::printf("[ scene_from_runs ] sampled squares' centres off the truth by at most %.2f px through the lens, %.2f px without\n",
              worst_a, worst_b);
  EXPECT_LE(worst_a, 0.5 + 1e-9);  // an integer square's centre is on the pixel grid or halfway
  EXPECT_GT(worst_b, 2.0);
}

}  // namespace
}  // namespace colorlab::verify
