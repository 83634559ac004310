#include "colorlab/analysis/chart_attitude.hpp"

#include <cmath>

namespace colorlab::analysis {

Eigen::Matrix3d chart_attitude_rotation(double rotation_deg, double tilt_deg, double swing_deg) {
  // −tilt about x takes the top edge (y < 0) to larger z, away from the camera; −swing about y takes the right edge
  // (x > 0) away likewise. Written as the simulator wrote it, so its seeded photographs stay the same to the bit.
  const double deg = M_PI / 180;
  return (Eigen::AngleAxisd(rotation_deg * deg, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(-tilt_deg * deg, Eigen::Vector3d::UnitX()) *
          Eigen::AngleAxisd(-swing_deg * deg, Eigen::Vector3d::UnitY()))
      .toRotationMatrix();
}

}  // namespace colorlab::analysis
