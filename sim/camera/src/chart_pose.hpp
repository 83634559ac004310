#pragma once
// The geometry of a posed chart: chart millimetres ↔ image positions through a pinhole camera with radial
// distortion. Image positions here are continuous with pixel (x, y) covering [x, x+1) × [y, y+1).
#include <Eigen/Dense>
#include <utility>

#include "colorlab/sim/camera/camera_model.hpp"

namespace colorlab::sim::camera::detail {

class PoseGeometry {
 public:
  PoseGeometry(const ChartPose& pose, int width, int height, double chart_height_fraction);
  std::pair<double, double> image_of(double chart_x_mm, double chart_y_mm) const;  // distorted
  std::pair<double, double> chart_of(double image_x, double image_y) const;        // from a distorted position
  // OpenCV convention (pixel centres at integers)
  LensIntrinsics intrinsics() const;

 private:
  Eigen::Matrix3d h_, inv_;
  double f_ = 0, fy_ = 0, cx_ = 0, cy_ = 0, k1_ = 0, k2_ = 0;
};

}  // namespace colorlab::sim::camera::detail
