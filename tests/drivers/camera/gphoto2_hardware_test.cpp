// On the bench with the lab's EOS 20D (USB, Communication = normal mode). Skips with the reason
// when no camera is attached, so CI runs it harmlessly. Bench command (see docs/PERFORMANCE.md, "Cameras"):
//   ctest --test-dir build -L hardware -R camera_gphoto2_hardware --output-on-failure
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/camera/gphoto2_camera.hpp"

namespace cam = colorlab::drivers::camera;
namespace fs = std::filesystem;

namespace {

std::optional<cam::DetectedCamera> attached_camera() {
  try {
    auto found = cam::gphoto2_autodetect();
    if (!found.empty()) return found.front();
  } catch (const colorlab::Error&) {
  }
  return std::nullopt;
}

}  // namespace

TEST(camera_gphoto2_hardware, captures_raw_and_raw_plus_jpeg_pairs) {
  const auto detected = attached_camera();
  if (!detected) GTEST_SKIP() << "no camera detected by libgphoto2 (hardware test: attach the EOS 20D by USB)";
  const fs::path keep = fs::temp_directory_path() / "colorlab-gphoto2-hw";
  cam::Gphoto2Options o;
  o.model = std::getenv("COLORLAB_CAMERA_MODEL") ? std::getenv("COLORLAB_CAMERA_MODEL") : detected->model;
  o.port = detected->port;
  o.keep_dir = keep;
  cam::Gphoto2Camera camera(o);
  camera.connect().get();
  const auto limits = camera.limits();
  ASSERT_FALSE(limits.iso.empty()) << "camera offers no iso widget: is it in PTP mode?";

  cam::CameraSettings s;
  s.image_format = cam::ImageFormat::raw;
  s.iso = limits.iso.front();
  camera.configure(s).get();
  auto report = camera
                    .capture(2,
                             [](const cam::RawImage& img) {
                               EXPECT_TRUE(img.cfa.is_mosaic());
                               EXPECT_GT(img.width, 1000U);
                               EXPECT_GT(img.white_level, img.black_level[0]);
                             })
                    .get();
  EXPECT_TRUE(report.complete()) << (report.error ? report.error->what() : "");
  EXPECT_EQ(report.saved_files.size(), 2U);

  if (std::find(limits.image_formats.begin(), limits.image_formats.end(), cam::ImageFormat::raw_and_jpeg) !=
      limits.image_formats.end()) {
    s = {};
    s.image_format = cam::ImageFormat::raw_and_jpeg;
    camera.configure(s).get();
    auto pair = camera.capture(1, [](const cam::RawImage&) {}).get();
    EXPECT_TRUE(pair.complete()) << (pair.error ? pair.error->what() : "");
    ASSERT_EQ(pair.saved_files.size(), 2U) << "JPEG partner not collected";
    EXPECT_EQ(pair.saved_files[0].stem(), pair.saved_files[1].stem());
  }
  fs::remove_all(keep);
}
