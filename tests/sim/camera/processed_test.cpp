// The camera's own processed output (camera-colour-space method, §7.1): its Adobe RGB, read through lcms2's
// Adobe RGB profile (analysis), lands near the scene's colorimetric truth — close, but not exact.
#include <gtest/gtest.h>
#include <tiffio.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "camera_fixture.hpp"
#include "colorlab/analysis/rgb_spaces.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/sim/camera/processed.hpp"

#ifdef COLORLAB_HAVE_LIBJPEG
#include <jpeglib.h>
#endif

namespace colorlab::sim::camera {
namespace {

namespace fs = std::filesystem;

std::array<double, 3> patch_rgb(const RgbImage& img, const CameraModel& cam, int patch) {
  const auto r = cam.patch_region(patch);
  std::array<double, 3> sum{};
  int n = 0;
  for (int y = r.y + r.height / 4; y < r.y + 3 * r.height / 4; ++y)
    for (int x = r.x + r.width / 4; x < r.x + 3 * r.width / 4; ++x, ++n)
      for (int c = 0; c < 3; ++c) sum[c] += img.rgb[(std::size_t(y) * img.width + x) * 3 + c] / 65535.0;
  for (double& s : sum) s /= n;
  return sum;
}

TEST(SimProcessed, AdobeRgbOutputIsNearTheScenesColorimetricTruth) {
  auto scene = test::d65_scene();
  const CameraModel cam(scene, test::small_camera(1050, 700));
  const CameraSettings s;
  const RawFrame frame = cam.render(s, 0);
  // Expose so that the white border patch A1 gets its true luminance factor.
  const auto lab_a1 = scene->patch_lab(0);
  const double y_a1 = std::pow((lab_a1[0] + 16) / 116, 3);
  DevelopSettings dev;
  dev.exposure = y_a1 * (frame.white_level - frame.black_level) / (cam.ground_truth(0, s)[1] - 256);
  const RgbImage img = develop(frame, cam, dev);
  ASSERT_EQ(img.rgb.size(), std::size_t(1050) * 700 * 3);
  std::vector<analysis::Rgb> rgb;
  for (int i = 0; i < chart_patch_count; ++i) rgb.push_back(patch_rgb(img, cam, i));
  const auto labs = analysis::rgb_to_lab_d50(analysis::RgbSpace::adobe_rgb_1998, rgb);
  double sum = 0, worst = 0;
  for (int i = 0; i < chart_patch_count; ++i) {
    const auto t = scene->patch_lab(i);
    const double de = std::hypot(labs[i].L - t[0], labs[i].a - t[1], labs[i].b - t[2]);
    sum += de;
    worst = std::max(worst, de);
  }
  const double mean = sum / chart_patch_count;
  std::printf("camera Adobe RGB vs truth: mean dE76 %.2f, max %.2f\n", mean, worst);
  // A camera matrix is never exact (the sensor is not colorimetric, the matrix is "pleasing", the field is
  // not uniform across the chart), but it is a usable colour space.
  EXPECT_GT(mean, 0.5);
  EXPECT_LT(mean, 8.0);
  // Neutral border patches come out neutral after the as-shot white balance.
  EXPECT_LT(std::hypot(labs[0].a, labs[0].b), 3.0);
}

class SimProcessedFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("colorlab_sim_proc_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    cam_ = std::make_unique<CameraModel>(test::d65_scene(), test::small_camera(320, 214));
    img_ = develop(cam_->render({}, 1), *cam_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
  std::unique_ptr<CameraModel> cam_;
  RgbImage img_;
};

std::vector<std::uint8_t> read_tiff(const fs::path& p, int& bits) {
  TIFF* t = TIFFOpen(p.c_str(), "r");
  if (!t) return {};
  std::uint32_t w = 0, h = 0;
  std::uint16_t b = 0, spp = 0;
  TIFFGetField(t, TIFFTAG_IMAGEWIDTH, &w);
  TIFFGetField(t, TIFFTAG_IMAGELENGTH, &h);
  TIFFGetField(t, TIFFTAG_BITSPERSAMPLE, &b);
  TIFFGetField(t, TIFFTAG_SAMPLESPERPIXEL, &spp);
  bits = b;
  std::vector<std::uint8_t> data(std::size_t(w) * h * spp * (b / 8));
  tmsize_t off = 0;
  for (tstrip_t s = 0; s < TIFFNumberOfStrips(t); ++s)
    off += TIFFReadEncodedStrip(t, s, data.data() + off, tmsize_t(data.size()) - off);
  TIFFClose(t);
  return data;
}

TEST_F(SimProcessedFiles, SixteenAndEightBitTiffsRoundTrip) {
  write_tiff(dir_ / "c16.tif", img_, 16);
  write_tiff(dir_ / "c8.tif", img_, 8);
  int bits = 0;
  const auto d16 = read_tiff(dir_ / "c16.tif", bits);
  ASSERT_EQ(bits, 16);
  ASSERT_EQ(d16.size(), img_.rgb.size() * 2);
  EXPECT_EQ(0, std::memcmp(d16.data(), img_.rgb.data(), d16.size()));
  const auto d8 = read_tiff(dir_ / "c8.tif", bits);
  ASSERT_EQ(bits, 8);
  ASSERT_EQ(d8.size(), img_.rgb.size());
  for (std::size_t i = 0; i < d8.size(); i += 97) EXPECT_NEAR(d8[i], img_.rgb[i] / 257.0, 0.51);
  EXPECT_THROW(write_tiff(dir_ / "x.tif", img_, 12), Error);
  EXPECT_THROW(write_tiff("/nonexistent-dir/x.tif", img_, 8), Error);
}

TEST_F(SimProcessedFiles, JpegDecodesCloseToTheEightBitImage) {
#ifndef COLORLAB_HAVE_LIBJPEG
  GTEST_SKIP() << "built without libjpeg";
#else
  write_jpeg(dir_ / "c.jpg", img_, 95);
  std::FILE* f = std::fopen((dir_ / "c.jpg").c_str(), "rb");
  ASSERT_NE(f, nullptr);
  jpeg_decompress_struct cinfo{};
  jpeg_error_mgr jerr{};
  cinfo.err = jpeg_std_error(&jerr);
  jpeg_create_decompress(&cinfo);
  jpeg_stdio_src(&cinfo, f);
  jpeg_read_header(&cinfo, TRUE);
  jpeg_start_decompress(&cinfo);
  ASSERT_EQ(int(cinfo.output_width), img_.width);
  ASSERT_EQ(int(cinfo.output_components), 3);
  std::vector<JSAMPLE> row(cinfo.output_width * 3);
  double abs_sum = 0;
  std::size_t n = 0;
  while (cinfo.output_scanline < cinfo.output_height) {
    const std::size_t y = cinfo.output_scanline;
    JSAMPROW rows[1] = {row.data()};
    jpeg_read_scanlines(&cinfo, rows, 1);
    for (std::size_t i = 0; i < row.size(); ++i, ++n) abs_sum += std::abs(row[i] - img_.rgb[y * row.size() + i] / 257.0);
  }
  jpeg_finish_decompress(&cinfo);
  jpeg_destroy_decompress(&cinfo);
  std::fclose(f);
  EXPECT_LT(abs_sum / double(n), 3.0);  // lossy, but quality 95
#endif
}

}  // namespace
}  // namespace colorlab::sim::camera
