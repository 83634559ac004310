#pragma once
// The chart's attitude before a camera — how the simulator poses its chart (sim/camera's ChartPose, ChartPlacement)
// and how the dry run pictures the lens-calibration campaign's poses (campaigns' dry_chart_centres) — as one rotation,
// so the two cannot disagree in sign (they once did: a positive tilt leaned the simulator's chart the wrong way).
//
// The convention, in the camera's coordinates (OpenCV's: x right, y down, z along the view) with the chart's own
// axes x along its rows (to its right edge) and y down its columns (to its bottom edge), facing the camera square-on
// at zero:
//   - rotation_deg turns the chart in the image plane, clockwise as the photograph shows it (y is down);
//   - a positive tilt_deg leans the chart's top edge (row 1) away from the camera, as a chart on the cabinet's floor
//     (row 1 at the back) leans for a camera at the open front;
//   - a positive swing_deg leans its right edge away from the camera.
// R = Rz(rotation) · Rx(−tilt) · Ry(−swing): swing first, then tilt, then the turn in the image plane. A chart point
// (X, Y, 0) about the chart's centre lies at R·(X, Y, 0) + t in the camera's coordinates.
#include <Eigen/Dense>

namespace colorlab::analysis {

Eigen::Matrix3d chart_attitude_rotation(double rotation_deg, double tilt_deg, double swing_deg);

}  // namespace colorlab::analysis
