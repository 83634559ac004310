#pragma once
// A small, fast simulated camera under D65 and a temporary capture directory per test.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <memory>

#include "colorlab/sim/camera/camera_model.hpp"

namespace colorlab::drivers::camera::test {

inline std::shared_ptr<sim::camera::CameraModel> small_model(int width = 640, int height = 428,
                                                             std::uint64_t seed = 1) {
  sim::SceneConfig scene;
  scene.seed = seed;
  scene.force_synthetic_chart = true;  // independent of the optional shared data set
  scene.lamps_on_at_start = {sim::Lamp::d65};
  auto s = std::make_shared<sim::Scene>(scene, std::make_shared<sim::SimClock>());
  sim::camera::CameraConfig cfg;
  cfg.width = width;
  cfg.height = height;
  cfg.threads = 1;
  return std::make_shared<sim::camera::CameraModel>(s, cfg);
}

class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() /
            ("colorlab-camdrv-" + std::to_string(::getpid()) + "-" + info->name());
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace colorlab::drivers::camera::test
