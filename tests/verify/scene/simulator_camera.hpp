#pragma once
// Where the simulator's DSLR stands in the cabinet for a ChartPose, derived from ChartPose's documented angles
// (camera_model.hpp: positive tilt leans the board's top edge away, positive swing its right edge) and the
// simulator's chart placement (Scene::chart_to_floor_mm: x along the board's width, y against its rows, z up out of
// the floor) — the truth the exported camera is held to. Written from the documentation, not copied from
// chart_pose.cpp: a copy of the code would agree with the code's sign whatever it was.
#include <Eigen/Dense>
#include <numbers>

#include "colorlab/sim/camera/camera_model.hpp"
#include "colorlab/sim/scene.hpp"

namespace colorlab::verify::testing {

struct SimulatorCamera {
  Eigen::Vector3d position_mm;  // cabinet frame
  Eigen::Vector3d axis;         // the optical axis, cabinet frame
};

// fx, fy: the lens's focal lengths in pixels (CameraModel::lens()); width, height: the frame.
inline SimulatorCamera simulator_camera(const sim::camera::ChartPose& p, double fx, double fy, int width, int height,
                                        const sim::Scene& scene) {
  const double deg = std::numbers::pi / 180;
  // Camera frame: x right, y down, z along the view. The board's top edge (y < 0) goes away from the camera (z up)
  // for a positive tilt: a rotation by −tilt about x; its right edge (x > 0) likewise for a positive swing.
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(p.rotation_deg * deg, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(-p.tilt_deg * deg, Eigen::Vector3d::UnitX()) *
                             Eigen::AngleAxisd(-p.swing_deg * deg, Eigen::Vector3d::UnitY()))
                                .toRotationMatrix();
  // Board point (X, Y) mm from its top-left → camera R·(X − W/2, Y − H/2, 0) + t, the board's centre at the
  // pose's distance and shifted by shift_x, shift_y of the frame.
  const Eigen::Vector3d t = R * Eigen::Vector3d(-sim::chart_width_mm / 2, -sim::chart_height_mm / 2, 0) +
                            Eigen::Vector3d(p.shift_x * width * p.distance_mm / fx, p.shift_y * height * p.distance_mm / fy,
                                            p.distance_mm);
  const Eigen::Vector3d c = -R.transpose() * t;  // camera centre, board coordinates (z into the board)
  const auto [x, y] = scene.chart_to_floor_mm(c.x(), c.y());
  const Eigen::Vector3d a = R.transpose() * Eigen::Vector3d::UnitZ();
  return {{x, y, -c.z()}, {a.x(), -a.y(), -a.z()}};
}

}  // namespace colorlab::verify::testing
