#include "chart_pose.hpp"

#include <cmath>
#include <random>

#include "colorlab/analysis/chart_attitude.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::sim::camera {

ChartPose random_chart_pose(std::uint64_t seed) {
  std::mt19937_64 rng(seed ^ 0x504F5345ull);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  ChartPose p;
  p.rotation_deg = 6 * u(rng);
  // Drawn with the sign that keeps every seeded pose's photograph as it was before the tilt and swing signs were
  // made to mean what ChartPose says (their rotations were the opposite): the same draws, the same images.
  p.tilt_deg = -15 * u(rng);
  p.swing_deg = -15 * u(rng);
  p.distance_mm = 900 + 400 * (u(rng) + 1) / 2;
  p.shift_x = 0.04 * u(rng);
  p.shift_y = 0.03 * u(rng);
  p.k1 = -0.08 * (u(rng) + 1) / 2;  // mild barrel
  p.k2 = 0.0;
  return p;
}

namespace detail {

PoseGeometry::PoseGeometry(const ChartPose& pose, int width, int height, double fraction) {
  if (!(pose.distance_mm > chart_width_mm))
    throw Error(ErrorClass::bad_parameter, "chart pose distance must exceed the chart's width (" + std::to_string(chart_width_mm) + " mm)");
  if (std::abs(pose.tilt_deg) >= 70 || std::abs(pose.swing_deg) >= 70)
    throw Error(ErrorClass::bad_parameter, "chart pose tilt and swing must be within ±70°");
  if (!(pose.fy_over_fx > 0.5 && pose.fy_over_fx < 2))
    throw Error(ErrorClass::bad_parameter, "chart pose fy_over_fx must be within (0.5, 2)");
  if (std::abs(pose.principal_dx_px) > width / 4.0 || std::abs(pose.principal_dy_px) > height / 4.0)
    throw Error(ErrorClass::bad_parameter, "chart pose principal point must stay within a quarter frame of the centre");
  const Eigen::Matrix3d R = analysis::chart_attitude_rotation(pose.rotation_deg, pose.tilt_deg, pose.swing_deg);
  f_ = fraction * height * pose.distance_mm / chart_height_mm;
  fy_ = f_ * pose.fy_over_fx;
  cx_ = width / 2.0 + pose.principal_dx_px, cy_ = height / 2.0 + pose.principal_dy_px;
  k1_ = pose.k1, k2_ = pose.k2;
  // Chart point (X, Y) mm from its top-left corner → camera coordinates R·(X − W/2, Y − H/2, 0) + t.
  const Eigen::Vector3d t = R * Eigen::Vector3d(-chart_width_mm / 2, -chart_height_mm / 2, 0) +
                            Eigen::Vector3d(pose.shift_x * width * pose.distance_mm / f_, pose.shift_y * height * pose.distance_mm / fy_,
                                            pose.distance_mm);
  Eigen::Matrix3d Rt;
  Rt.col(0) = R.col(0), Rt.col(1) = R.col(1), Rt.col(2) = t;
  Eigen::Matrix3d K;
  K << f_, 0, cx_, 0, fy_, cy_, 0, 0, 1;
  h_ = K * Rt;
  inv_ = h_.inverse();
}

std::pair<double, double> PoseGeometry::image_of(double X, double Y) const {
  const Eigen::Vector3d v = h_ * Eigen::Vector3d(X, Y, 1);
  const double x = (v(0) / v(2) - cx_) / f_, y = (v(1) / v(2) - cy_) / fy_, r2 = x * x + y * y;
  const double k = 1 + k1_ * r2 + k2_ * r2 * r2;
  return {cx_ + f_ * x * k, cy_ + fy_ * y * k};
}

std::pair<double, double> PoseGeometry::chart_of(double u, double v) const {
  const double xd = (u - cx_) / f_, yd = (v - cy_) / fy_;
  double x = xd, y = yd;
  for (int i = 0; i < 8; ++i) {  // fixed point: converges for the mild distortions of a bench lens
    const double r2 = x * x + y * y, k = 1 + k1_ * r2 + k2_ * r2 * r2;
    x = xd / k, y = yd / k;
  }
  const Eigen::Vector3d c = inv_ * Eigen::Vector3d(cx_ + f_ * x, cy_ + fy_ * y, 1);
  if (c(2) <= 0) return {-1e9, -1e9};  // beyond the chart plane's horizon
  return {c(0) / c(2), c(1) / c(2)};
}

LensIntrinsics PoseGeometry::intrinsics() const { return {f_, fy_, cx_ - 0.5, cy_ - 0.5, k1_, k2_}; }

}  // namespace detail
}  // namespace colorlab::sim::camera
