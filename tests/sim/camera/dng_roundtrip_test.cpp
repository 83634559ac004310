// The simulated camera's DNG decodes back exactly through LibRaw (and dcraw -D -4 when installed).
#include <gtest/gtest.h>
#include <libraw/libraw.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "camera_fixture.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/sim/camera/dng.hpp"

namespace colorlab::sim::camera {
namespace {

namespace fs = std::filesystem;

class SimDngTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("colorlab_sim_dng_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

DngMetadata metadata_for(const CameraModel& cam) {
  DngMetadata m;
  m.color_matrix1 = cam.xyz_to_camera_d65();
  m.as_shot_neutral = cam.as_shot_neutral();
  return m;
}

TEST_F(SimDngTest, LibRawDecodesEveryCountExactly) {
  const CameraModel cam(test::d65_scene(), test::small_camera(704, 470));
  const RawFrame frame = cam.render({}, 11);
  const fs::path path = dir_ / "frame.dng";
  write_dng(path, frame, metadata_for(cam));
  ASSERT_TRUE(fs::exists(path));
  for (const auto& e : fs::directory_iterator(dir_)) EXPECT_EQ(e.path().filename(), "frame.dng");  // no temp left

  LibRaw raw;
  ASSERT_EQ(raw.open_file(path.c_str()), LIBRAW_SUCCESS);
  ASSERT_EQ(raw.unpack(), LIBRAW_SUCCESS);
  EXPECT_STREQ(raw.imgdata.idata.make, "colorlab");
  EXPECT_TRUE(raw.imgdata.idata.dng_version != 0);
  ASSERT_EQ(raw.imgdata.sizes.raw_width, frame.width);
  ASSERT_EQ(raw.imgdata.sizes.raw_height, frame.height);
  ASSERT_NE(raw.imgdata.rawdata.raw_image, nullptr);
  EXPECT_EQ(raw.imgdata.color.black, 256u);
  EXPECT_EQ(raw.imgdata.color.maximum, 4095u);
  const int pitch = raw.imgdata.sizes.raw_pitch / 2;
  long differing = 0;
  for (int y = 0; y < frame.height; ++y)
    for (int x = 0; x < frame.width; ++x)
      differing += raw.imgdata.rawdata.raw_image[y * pitch + x] != frame.at(x, y);
  EXPECT_EQ(differing, 0);
  // RGGB: LibRaw's COLOR() of the top-left 2×2 block.
  EXPECT_EQ(raw.COLOR(0, 0), 0);
  EXPECT_EQ(raw.COLOR(1, 1), 2);
  // AsShotNeutral → camera multipliers (1/neutral, normalised to G).
  const auto neutral = cam.as_shot_neutral();
  EXPECT_NEAR(raw.imgdata.color.cam_mul[0] / raw.imgdata.color.cam_mul[1], 1.0 / neutral[0], 1e-3);
}

TEST_F(SimDngTest, DcrawDocumentModeAgrees) {
  if (std::system("command -v dcraw >/dev/null 2>&1") != 0) GTEST_SKIP() << "dcraw not installed";
  const CameraModel cam(test::d65_scene(), test::small_camera(256, 170));
  const RawFrame frame = cam.render({}, 2);
  const fs::path path = dir_ / "d.dng";
  write_dng(path, frame, metadata_for(cam));
  ASSERT_EQ(std::system(("dcraw -D -4 " + path.string()).c_str()), 0);
  std::ifstream pgm(dir_ / "d.pgm", std::ios::binary);
  ASSERT_TRUE(pgm);
  std::string magic;
  int w = 0, h = 0, maxval = 0;
  pgm >> magic >> w >> h >> maxval;
  pgm.get();
  ASSERT_EQ(magic, "P5");
  ASSERT_EQ(w, frame.width);
  ASSERT_EQ(h, frame.height);
  long differing = 0;
  for (int i = 0; i < w * h; ++i) {
    const int hi = pgm.get(), lo = pgm.get();
    differing += ((hi << 8) | lo) != frame.pixels[static_cast<std::size_t>(i)];
  }
  EXPECT_EQ(differing, 0);
}

TEST_F(SimDngTest, SameFrameGivesTheSameBytes) {
  const CameraModel cam(test::d65_scene(), test::small_camera(256, 170));
  const auto m = metadata_for(cam);
  write_dng(dir_ / "a.dng", cam.render({}, 5), m);
  write_dng(dir_ / "b.dng", cam.render({}, 5), m);
  auto slurp = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  };
  EXPECT_EQ(slurp(dir_ / "a.dng"), slurp(dir_ / "b.dng"));
  EXPECT_GT(fs::file_size(dir_ / "a.dng"), 256u * 170u * 2u);
}

TEST_F(SimDngTest, BadInputsGiveTypedErrors) {
  RawFrame bad;
  bad.width = 10;
  bad.height = 10;
  bad.pixels.resize(99);
  try {
    write_dng(dir_ / "x.dng", bad, {});
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::bad_parameter);
  }
  const CameraModel cam(test::d65_scene(), test::small_camera(128, 86));
  try {
    write_dng("/nonexistent-dir/x.dng", cam.render({}, 0), {});
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::io_error);
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir"), std::string::npos);
  }
}

}  // namespace
}  // namespace colorlab::sim::camera
