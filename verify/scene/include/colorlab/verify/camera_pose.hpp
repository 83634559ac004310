#pragma once
// The camera's pose from the located chart (issue 23, docs/verify.md "The measured scene", camera): the chart
// locator's four outer corners of the patch grid on the photograph and the chart's known geometry, lying flat on
// the floor where the cabinet puts it, give the camera's position and orientation by OpenCV's solvePnP (IPPE, the
// planar case), with the lens's intrinsics. The corners' stated accuracy (one σ per coordinate, pixels) is carried
// to the pose through the numerical Jacobian of that solution, so the export says how well it knows the camera.
#include <array>
#include <string>

namespace colorlab::verify {

// OpenCV's pinhole + radial model in pixels of the photograph (pixel centres at integers).
struct CameraIntrinsics {
  double fx = 0, fy = 0, cx = 0, cy = 0, k1 = 0, k2 = 0;
};

struct ChartSighting {
  // Outer corners of the patch grid in reading order (A1's, N1's, N10's, A10's on an SG), photograph pixels.
  std::array<std::array<double, 2>, 4> corners_px{};
  // The same corners in the cabinet's frame (mm; x from the left wall, y from the front, z up).
  std::array<std::array<double, 3>, 4> corners_mm{};
  double accuracy_px = 0.5;  // one σ per corner coordinate
};

struct CameraPose {
  std::array<double, 3> position_mm{};
  // Columns: the camera's x (image right), y (image down) and z (optical axis) in the cabinet's frame.
  std::array<std::array<double, 3>, 3> axes{};
  std::array<double, 3> position_sigma_mm{};  // one σ per cabinet axis: both parts below in quadrature
  double axis_sigma_deg = 0;                  // one σ of the optical axis' direction
  double reprojection_px = 0;                 // RMS of the corners against the solved pose
  // The two parts: the corners' stated accuracy, and the lens calibration's own σ of fx, fy, cx, cy, k1, k2.
  std::array<double, 3> position_sigma_corners_mm{}, position_sigma_lens_mm{};
  double axis_sigma_corners_deg = 0, axis_sigma_lens_deg = 0;
};

// `lens_sigma`: one standard uncertainty of each intrinsic (a stored lens calibration's `sigma`; zeros for a lens
// taken as exact), carried through the same numerical Jacobian as the corners, the parameters taken as independent
// (the calibration states no covariance). Throws Error(bad_parameter) for intrinsics without a focal length or a
// negative σ, Error(bad_data) for corners that give no pose in front of the camera (a degenerate or mirrored
// quadrilateral).
CameraPose pose_from_chart(const ChartSighting& sighting, const CameraIntrinsics& lens, const CameraIntrinsics& lens_sigma = {});

}  // namespace colorlab::verify
