#include "floor_view.hpp"

#include <cmath>

#include "colorlab/sim/scene.hpp"

namespace colorlab::sim::camera::detail {

namespace {
// Where the camera stands: its axis meets the middle of the floor 1.6 m away, tilted 35° from looking straight
// down the cabinet, so the back edge lies farther than the front and the floor is a trapezoid in the frame.
constexpr double kDistanceMm = 1600.0;
constexpr double kTiltDeg = 35.0;
// The floor's front edge (the nearest, so the widest) spans this fraction of the frame's width.
constexpr double kFrontFill = 0.94;
}  // namespace

FloorGeometry::FloorGeometry(int width, int height, double k1, double k2) : k1_(k1), k2_(k2) {
  const double a = kTiltDeg * M_PI / 180.0, s = std::sin(a), c = std::cos(a);
  const double half_w = cabinet_width_mm / 2, half_d = cabinet_depth_mm / 2;
  cx_ = width / 2.0;
  cy_ = height / 2.0;
  f_ = kFrontFill * (width / 2.0) * (kDistanceMm - half_d * s) / half_w;
  // Floor point (x, y) → plane coordinates u = x − W/2 (right), v = D/2 − y (towards the front, image down) →
  // camera (u, v·cos a, d − v·sin a): the back edge (v < 0) leans away from the camera.
  Eigen::Matrix3d plane;
  plane << 1, 0, -half_w, 0, -1, half_d, 0, 0, 1;
  Eigen::Matrix3d rt;
  rt << 1, 0, 0, 0, c, 0, 0, -s, kDistanceMm;
  Eigen::Matrix3d k;
  k << f_, 0, cx_, 0, f_, cy_, 0, 0, 1;
  h_ = k * rt * plane;
  inv_ = h_.inverse();
}

std::pair<double, double> FloorGeometry::pinhole_of(double x, double y) const {
  const Eigen::Vector3d v = h_ * Eigen::Vector3d(x, y, 1);
  return {v(0) / v(2), v(1) / v(2)};
}

std::pair<double, double> FloorGeometry::image_of(double x, double y) const {
  const auto [u, v] = pinhole_of(x, y);
  if (k1_ == 0 && k2_ == 0) return {u, v};  // the distortion-free view, bit for bit as before the lens existed
  const double a = (u - cx_) / f_, b = (v - cy_) / f_, r2 = a * a + b * b, k = 1 + k1_ * r2 + k2_ * r2 * r2;
  return {cx_ + f_ * a * k, cy_ + f_ * b * k};
}

std::pair<double, double> FloorGeometry::floor_of(double u, double v) const {
  if (k1_ != 0 || k2_ != 0) {
    const double ad = (u - cx_) / f_, bd = (v - cy_) / f_;
    double a = ad, b = bd;
    for (int i = 0; i < 20; ++i) {  // fixed point, as chart_pose.cpp: converges for a bench lens's mild distortion
      const double r2 = a * a + b * b, k = 1 + k1_ * r2 + k2_ * r2 * r2;
      a = ad / k, b = bd / k;
    }
    u = cx_ + f_ * a, v = cy_ + f_ * b;
  }
  const Eigen::Vector3d p = inv_ * Eigen::Vector3d(u, v, 1);
  if (p(2) <= 0) return {-1e9, -1e9};  // above the floor's horizon
  return {p(0) / p(2), p(1) / p(2)};
}

double FloorGeometry::cos4(double u, double v) const {
  const double r2 = ((u - cx_) * (u - cx_) + (v - cy_) * (v - cy_)) / (f_ * f_);
  return 1.0 / ((1.0 + r2) * (1.0 + r2));
}

}  // namespace colorlab::sim::camera::detail
