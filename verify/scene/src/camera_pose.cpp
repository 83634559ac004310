#include "colorlab/verify/camera_pose.hpp"

#include <cmath>
#include <numbers>
#include <vector>

#include <opencv2/calib3d.hpp>

#include "colorlab/core/error.hpp"

namespace colorlab::verify {

namespace {

struct Solved {
  cv::Vec3d centre;
  cv::Matx33d r;  // cabinet → camera
  double rms = 0;
};

Solved solve(const std::array<std::array<double, 2>, 4>& px, const std::array<std::array<double, 3>, 4>& mm,
             const CameraIntrinsics& k) {
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (std::size_t i = 0; i < 4; ++i) {
    object.emplace_back(mm[i][0], mm[i][1], mm[i][2]);
    image.emplace_back(px[i][0], px[i][1]);
  }
  const cv::Matx33d camera(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  const cv::Vec4d dist(k.k1, k.k2, 0, 0);
  cv::Vec3d rvec, tvec;
  // IPPE: the planar case's closed form (4 coplanar points), the better of its two solutions.
  if (!cv::solvePnP(object, image, camera, dist, rvec, tvec, false, cv::SOLVEPNP_IPPE))
    throw Error(ErrorClass::bad_data, "camera pose: solvePnP found no pose for the chart's corners",
                "the corners must be the chart's four outer grid corners in reading order");
  Solved s;
  cv::Rodrigues(rvec, s.r);
  s.centre = -(s.r.t() * tvec);
  std::vector<cv::Point2d> back;
  cv::projectPoints(object, rvec, tvec, camera, dist, back);
  double ss = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    const cv::Vec3d c = s.r * cv::Vec3d(object[i].x, object[i].y, object[i].z) + tvec;
    if (!(c[2] > 0))
      throw Error(ErrorClass::bad_data, "camera pose: the chart's corners give a pose with the chart behind the camera",
                  "check the corners' order (A1's first, clockwise as the chart reads)");
    ss += std::pow(back[i].x - image[i].x, 2) + std::pow(back[i].y - image[i].y, 2);
  }
  s.rms = std::sqrt(ss / 4);
  return s;
}

cv::Vec3d optical_axis(const Solved& s) { return cv::Vec3d(s.r(2, 0), s.r(2, 1), s.r(2, 2)); }

}  // namespace

CameraPose pose_from_chart(const ChartSighting& sighting, const CameraIntrinsics& lens, const CameraIntrinsics& lens_sigma) {
  if (!(lens.fx > 0 && lens.fy > 0))
    throw Error(ErrorClass::bad_parameter, "camera pose: the lens needs positive focal lengths fx, fy (pixels)");
  double CameraIntrinsics::*const params[] = {&CameraIntrinsics::fx, &CameraIntrinsics::fy, &CameraIntrinsics::cx,
                                              &CameraIntrinsics::cy, &CameraIntrinsics::k1, &CameraIntrinsics::k2};
  for (auto m : params)
    if (!(lens_sigma.*m >= 0))
      throw Error(ErrorClass::bad_parameter, "camera pose: the lens calibration's uncertainties must be ≥ 0",
                  "a [[lens]] table's sigma states one standard uncertainty of each parameter");
  if (!(sighting.accuracy_px >= 0))
    throw Error(ErrorClass::bad_parameter, "camera pose: the corners' accuracy must be ≥ 0 px");
  const Solved s = solve(sighting.corners_px, sighting.corners_mm, lens);
  CameraPose p;
  for (int i = 0; i < 3; ++i) {
    p.position_mm[static_cast<std::size_t>(i)] = s.centre[i];
    for (int j = 0; j < 3; ++j) p.axes[static_cast<std::size_t>(j)][static_cast<std::size_t>(i)] = s.r(j, i);
  }
  p.reprojection_px = s.rms;
  // σ of the pose from σ of each corner coordinate: central differences of the solution, summed in quadrature
  // (the eight coordinates independent).
  const double h = 0.05;
  cv::Vec3d var_pos(0, 0, 0);
  double var_axis = 0;
  for (std::size_t c = 0; c < 4; ++c)
    for (std::size_t a = 0; a < 2; ++a) {
      auto plus = sighting.corners_px, minus = sighting.corners_px;
      plus[c][a] += h, minus[c][a] -= h;
      const Solved sp = solve(plus, sighting.corners_mm, lens), sm = solve(minus, sighting.corners_mm, lens);
      const cv::Vec3d dp = (sp.centre - sm.centre) / (2 * h);
      const cv::Vec3d da = (optical_axis(sp) - optical_axis(sm)) / (2 * h);
      for (int i = 0; i < 3; ++i) var_pos[i] += dp[i] * dp[i];
      var_axis += da.dot(da);
    }
  const double sd = sighting.accuracy_px, deg = 180.0 / std::numbers::pi;
  for (int i = 0; i < 3; ++i) p.position_sigma_corners_mm[static_cast<std::size_t>(i)] = sd * std::sqrt(var_pos[i]);
  p.axis_sigma_corners_deg = sd * std::sqrt(var_axis) * deg;

  // The lens calibration's σ: each parameter moved by a tenth of its σ either way (small enough to stay linear, the
  // same solution branch), the change scaled to one σ.
  cv::Vec3d lens_pos(0, 0, 0);
  double lens_axis = 0;
  for (auto m : params) {
    const double u = lens_sigma.*m;
    if (!(u > 0)) continue;
    CameraIntrinsics plus = lens, minus = lens;
    plus.*m += 0.1 * u, minus.*m -= 0.1 * u;
    const Solved sp = solve(sighting.corners_px, sighting.corners_mm, plus), sm = solve(sighting.corners_px, sighting.corners_mm, minus);
    const cv::Vec3d dp = (sp.centre - sm.centre) / 0.2;
    const cv::Vec3d da = (optical_axis(sp) - optical_axis(sm)) / 0.2;
    for (int i = 0; i < 3; ++i) lens_pos[i] += dp[i] * dp[i];
    lens_axis += da.dot(da);
  }
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    p.position_sigma_lens_mm[k] = std::sqrt(lens_pos[i]);
    p.position_sigma_mm[k] = std::hypot(p.position_sigma_corners_mm[k], p.position_sigma_lens_mm[k]);
  }
  p.axis_sigma_lens_deg = std::sqrt(lens_axis) * deg;
  p.axis_sigma_deg = std::hypot(p.axis_sigma_corners_deg, p.axis_sigma_lens_deg);
  return p;
}

}  // namespace colorlab::verify
