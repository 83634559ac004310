#include "chart_pose.hpp"

#include <cmath>
#include <random>

#include "colorlab/core/error.hpp"

namespace colorlab::sim::camera {

ChartPose random_chart_pose(std::uint64_t seed) {
  std::mt19937_64 rng(seed ^ 0x504F5345ull);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  ChartPose p;
  p.rotation_deg = 6 * u(rng);
  p.tilt_deg = 15 * u(rng);
  p.swing_deg = 15 * u(rng);
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
  const double deg = M_PI / 180;
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(pose.rotation_deg * deg, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(pose.tilt_deg * deg, Eigen::Vector3d::UnitX()) *
                             Eigen::AngleAxisd(pose.swing_deg * deg, Eigen::Vector3d::UnitY()))
                                .toRotationMatrix();
  f_ = fraction * height * pose.distance_mm / chart_height_mm;
  cx_ = width / 2.0, cy_ = height / 2.0;
  k1_ = pose.k1, k2_ = pose.k2;
  // Chart point (X, Y) mm from its top-left corner → camera coordinates R·(X − W/2, Y − H/2, 0) + t.
  const Eigen::Vector3d t = R * Eigen::Vector3d(-chart_width_mm / 2, -chart_height_mm / 2, 0) +
                            Eigen::Vector3d(pose.shift_x * width * pose.distance_mm / f_, pose.shift_y * height * pose.distance_mm / f_,
                                            pose.distance_mm);
  Eigen::Matrix3d Rt;
  Rt.col(0) = R.col(0), Rt.col(1) = R.col(1), Rt.col(2) = t;
  Eigen::Matrix3d K;
  K << f_, 0, cx_, 0, f_, cy_, 0, 0, 1;
  h_ = K * Rt;
  inv_ = h_.inverse();
}

std::pair<double, double> PoseGeometry::image_of(double X, double Y) const {
  const Eigen::Vector3d v = h_ * Eigen::Vector3d(X, Y, 1);
  const double x = (v(0) / v(2) - cx_) / f_, y = (v(1) / v(2) - cy_) / f_, r2 = x * x + y * y;
  const double k = 1 + k1_ * r2 + k2_ * r2 * r2;
  return {cx_ + f_ * x * k, cy_ + f_ * y * k};
}

std::pair<double, double> PoseGeometry::chart_of(double u, double v) const {
  const double xd = (u - cx_) / f_, yd = (v - cy_) / f_;
  double x = xd, y = yd;
  for (int i = 0; i < 8; ++i) {  // fixed point: converges for the mild distortions of a bench lens
    const double r2 = x * x + y * y, k = 1 + k1_ * r2 + k2_ * r2 * r2;
    x = xd / k, y = yd / k;
  }
  const Eigen::Vector3d c = inv_ * Eigen::Vector3d(cx_ + f_ * x, cy_ + f_ * y, 1);
  if (c(2) <= 0) return {-1e9, -1e9};  // beyond the chart plane's horizon
  return {c(0) / c(2), c(1) / c(2)};
}

LensIntrinsics PoseGeometry::intrinsics() const { return {f_, f_, cx_ - 0.5, cy_ - 0.5, k1_, k2_}; }

}  // namespace detail
}  // namespace colorlab::sim::camera
