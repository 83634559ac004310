#pragma once
// A small simulated camera (fast) looking at the chart under D65.
#include <memory>

#include "colorlab/sim/camera/camera_model.hpp"

namespace colorlab::sim::camera::test {

inline std::shared_ptr<Scene> d65_scene(std::uint64_t seed = 1, bool synthetic = true) {
  SceneConfig cfg;
  cfg.seed = seed;
  cfg.force_synthetic_chart = synthetic;
  cfg.lamps_on_at_start = {Lamp::d65};
  return std::make_shared<Scene>(cfg, std::make_shared<SimClock>());
}

inline CameraConfig small_camera(int width = 700, int height = 468) {
  CameraConfig c;
  c.width = width;
  c.height = height;
  c.force_parametric_sensitivities = false;
  return c;
}

}  // namespace colorlab::sim::camera::test
