#pragma once
// The geometry of the camera aimed at the empty cabinet floor (CameraModel::View::floor): a rectilinear lens on
// the cabinet's open front, above the front edge, its optical axis through the middle of the floor. Floor
// millimetres (x from the left wall, y from the front edge, as the scene's) ↔ image positions through a plane
// homography, then the lens's radial distortion (OpenCV's k1, k2 about the frame's centre; none by default); image
// positions are continuous with pixel (x, y) covering [x, x+1) × [y, y+1).
#include <Eigen/Dense>
#include <utility>

namespace colorlab::sim::camera::detail {

class FloorGeometry {
 public:
  FloorGeometry(int width, int height, double k1 = 0, double k2 = 0);
  std::pair<double, double> image_of(double floor_x_mm, double floor_y_mm) const;    // distorted
  std::pair<double, double> pinhole_of(double floor_x_mm, double floor_y_mm) const;  // without the distortion
  std::pair<double, double> floor_of(double image_x, double image_y) const;          // from a distorted position
  double focal_px() const { return f_; }
  double cx() const { return cx_; }
  double cy() const { return cy_; }
  double k1() const { return k1_; }
  double k2() const { return k2_; }
  // cos⁴ of the angle off the optical axis at an image position: the natural fall-off of a wide view, which a
  // chart filling a long lens's frame barely shows but a floor seen from 1.6 m across 1.2 m does.
  double cos4(double image_x, double image_y) const;

 private:
  Eigen::Matrix3d h_, inv_;
  double f_ = 0, cx_ = 0, cy_ = 0, k1_ = 0, k2_ = 0;
};

}  // namespace colorlab::sim::camera::detail
