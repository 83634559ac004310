// The chart's attitude as one rotation (chart_attitude.hpp), pinned against rotations worked out by hand from the
// documented convention — not from the Eigen expression it is built with: a positive tilt takes the top edge away
// from the camera, a positive swing the right edge, a positive rotation turns the chart clockwise as photographed
// (y down), and swing comes first, then tilt, then the turn. The simulator and the dry run both pose the chart with
// it; a sign or an order changed in it fails here, not in a lens calibration that quietly fits the wrong side.
#include <gtest/gtest.h>

#include <cmath>

#include "colorlab/analysis/chart_attitude.hpp"

namespace colorlab::analysis {
namespace {

const double kC30 = std::sqrt(3.0) / 2, kS30 = 0.5;

Eigen::Vector3d v(double x, double y, double z) { return Eigen::Vector3d(x, y, z); }

void expect_maps(double rotation, double tilt, double swing, const Eigen::Vector3d& from, const Eigen::Vector3d& to, const char* what) {
  const Eigen::Vector3d got = chart_attitude_rotation(rotation, tilt, swing) * from;
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(got(i), to(i), 1e-12) << what << ": component " << i << " of " << got.transpose();
}

TEST(ChartAttitude, EachAngleLeansTheWayTheConventionSays) {
  expect_maps(0, 0, 0, v(0.3, -0.7, 0.2), v(0.3, -0.7, 0.2), "square-on");
  // Tilt 30°: the top edge's middle (y = −1) goes back (z > 0), the bottom edge's comes forward; x stays.
  expect_maps(0, 30, 0, v(0, -1, 0), v(0, -kC30, kS30), "tilt: top edge");
  expect_maps(0, 30, 0, v(0, 1, 0), v(0, kC30, -kS30), "tilt: bottom edge");
  expect_maps(0, 30, 0, v(1, 0, 0), v(1, 0, 0), "tilt: the horizontal axis");
  // Swing 30°: the right edge goes back, the left comes forward; y stays.
  expect_maps(0, 0, 30, v(1, 0, 0), v(kC30, 0, kS30), "swing: right edge");
  expect_maps(0, 0, 30, v(-1, 0, 0), v(-kC30, 0, -kS30), "swing: left edge");
  expect_maps(0, 0, 30, v(0, 1, 0), v(0, 1, 0), "swing: the vertical axis");
  // Rotation 30°: the right edge turns down the photograph (y is down: clockwise as seen); the view axis stays.
  expect_maps(30, 0, 0, v(1, 0, 0), v(kC30, kS30, 0), "rotation: right edge");
  expect_maps(30, 0, 0, v(0, -1, 0), v(kS30, -kC30, 0), "rotation: top edge");
  expect_maps(30, 0, 0, v(0, 0, 1), v(0, 0, 1), "rotation: the view axis");
  // Negative angles lean the other way.
  expect_maps(0, -30, 0, v(0, -1, 0), v(0, -kC30, -kS30), "negative tilt: top edge comes forward");
  expect_maps(0, 0, -30, v(1, 0, 0), v(kC30, 0, -kS30), "negative swing: right edge comes forward");
}

TEST(ChartAttitude, SwingFirstThenTiltThenTheTurn) {
  // All three at 90°, by hand: the swing takes the right edge (1, 0, 0) straight back to the view axis (0, 0, 1); the
  // tilt, leaning the top (0, −1, 0) back to (0, 0, 1), takes the view axis down to (0, 1, 0); the clockwise turn takes
  // down to left, (−1, 0, 0). In any other order the right edge ends elsewhere (tilt before swing: (0, 0, 1)).
  expect_maps(90, 90, 90, v(1, 0, 0), v(-1, 0, 0), "right edge");
  // The bottom edge: the swing leaves it; the tilt brings it forward to (0, 0, −1); the turn leaves the view axis.
  expect_maps(90, 90, 90, v(0, 1, 0), v(0, 0, -1), "bottom edge");
  // The chart's normal towards the camera (0, 0, −1): the swing turns it to (1, 0, 0), the tilt leaves x, the turn
  // takes right to down.
  expect_maps(90, 90, 90, v(0, 0, -1), v(0, 1, 0), "normal");
}

TEST(ChartAttitude, ARotationAndWhatAPinholeSeesOfATiltedChart) {
  const Eigen::Matrix3d R = chart_attitude_rotation(-4.5, 17, 23);
  EXPECT_NEAR((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 0, 1e-14);
  EXPECT_NEAR(R.determinant(), 1, 1e-14);
  // A 262 × 186 mm chart 600 mm in front of a pinhole, tilted 20°: its top edge, farther, is photographed shorter than
  // its bottom edge — by the ratio of their distances, worked out by hand: 600 ± 93·sin 20°.
  const Eigen::Matrix3d T = chart_attitude_rotation(0, 20, 0);
  const auto width_at = [&](double y) {
    const Eigen::Vector3d l = T * Eigen::Vector3d(-131, y, 0) + Eigen::Vector3d(0, 0, 600);
    const Eigen::Vector3d r = T * Eigen::Vector3d(131, y, 0) + Eigen::Vector3d(0, 0, 600);
    return r(0) / r(2) - l(0) / l(2);
  };
  const double s20 = std::sin(20 * M_PI / 180);
  EXPECT_NEAR(width_at(93) / width_at(-93), (600 + 93 * s20) / (600 - 93 * s20), 1e-12);
  EXPECT_LT(width_at(-93), width_at(93));
}

}  // namespace
}  // namespace colorlab::analysis
