// The simulated DSLR end to end: render -> real DNG on disk -> LibRaw -> sink/accumulator, its
// settings and limits, the pipeline overlap, and every injectable fault ending in a typed error
// with a partial (never complete) report.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <future>
#include <thread>

#include "colorlab/analysis/frame_accumulator.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/drivers/camera/simulated_camera.hpp"
#include "sim_fixture.hpp"

namespace cam = colorlab::drivers::camera;
namespace simcam = colorlab::sim::camera;
namespace fs = std::filesystem;
using colorlab::ErrorClass;

namespace {

struct Rig {
  cam::test::TempDir dir;
  std::shared_ptr<simcam::CameraModel> model = cam::test::small_model();
  std::unique_ptr<cam::SimulatedCamera> camera;

  explicit Rig(std::chrono::milliseconds extra = std::chrono::milliseconds(0)) {
    cam::SimulatedCameraOptions o;
    o.model = model;
    o.capture_dir = dir.path();
    o.extra_capture_time = extra;
    o.timeout_after = std::chrono::milliseconds(20);
    camera = std::make_unique<cam::SimulatedCamera>(o);
    camera->connect().get();
  }
};

std::size_t dng_files(const fs::path& dir) {
  std::size_t n = 0;
  for (const auto& e : fs::directory_iterator(dir)) n += e.path().extension() == ".DNG";
  return n;
}

const cam::CaptureReport capture_n(cam::Camera& c, std::size_t n) {
  return c.capture(n, [](const cam::RawImage&) {}).get();
}

}  // namespace

TEST(camera_simulated, frames_arrive_through_dng_and_libraw_bit_exact) {
  Rig rig;
  EXPECT_EQ(rig.camera->identity().kind, cam::CameraKind::simulated);
  std::vector<cam::OwnedRawImage> got;
  auto report = rig.camera->capture(3, [&](const cam::RawImage& img) { got.push_back(cam::OwnedRawImage::copy_of(img)); }).get();
  ASSERT_TRUE(report.complete()) << (report.error ? report.error->what() : "");
  ASSERT_EQ(got.size(), 3U);
  EXPECT_EQ(report.saved_files.size(), 3U);
  EXPECT_EQ(dng_files(rig.dir.path()), 3U);
  for (std::size_t k = 0; k < got.size(); ++k) {
    const auto truth = rig.model->render(rig.camera->model_settings(), k);  // shot k of this camera
    const auto img = got[k].view();
    EXPECT_EQ(img.frame_index, k);
    EXPECT_EQ(img.cfa, cam::CfaPattern::rggb());
    EXPECT_EQ(img.black_level[0], truth.black_level);
    EXPECT_EQ(img.white_level, truth.white_level);
    ASSERT_EQ(img.width, static_cast<std::size_t>(truth.width));
    EXPECT_TRUE(std::equal(truth.pixels.begin(), truth.pixels.end(), img.contiguous().begin())) << "frame " << k;
  }
}

TEST(camera_simulated, averaged_patches_match_scene_ground_truth) {
  Rig rig;
  cam::CameraSettings s;
  s.iso = 100;
  s.shutter_s = 1.0 / 30;
  s.aperture_f = 4;
  rig.camera->configure(s).get();
  colorlab::analysis::FrameAccumulator acc(static_cast<std::size_t>(rig.model->width()),
                                           static_cast<std::size_t>(rig.model->height()));
  const auto report = rig.camera->capture(4, [&](const cam::RawImage& img) { acc.add(img.contiguous()); }).get();
  ASSERT_TRUE(report.complete()) << (report.error ? report.error->what() : "");
  EXPECT_EQ(acc.frames(), 4U);
  const auto mean = acc.mean();
  const auto truth = rig.model->ground_truth(rig.camera->model_settings());
  int checked = 0;
  for (int p = 0; p < 140; p += 7) {
    const auto r = rig.model->patch_region(p);
    for (int ch = 0; ch < 3; ++ch) {
      std::vector<float> v;  // inner half of the patch: clear of edges; median: clear of dust
      for (int y = r.y + r.height / 4; y < r.y + 3 * r.height / 4; ++y) {
        for (int x = r.x + r.width / 4; x < r.x + 3 * r.width / 4; ++x) {
          if (simcam::rggb_channel(x, y) == ch) v.push_back(mean[static_cast<std::size_t>(y * rig.model->width() + x)]);
        }
      }
      ASSERT_FALSE(v.empty());
      std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
      const double median = v[v.size() / 2];
      const double expected = truth[static_cast<std::size_t>(p)][static_cast<std::size_t>(ch)];
      EXPECT_NEAR(median, expected, std::max(4.0, 0.02 * (expected - 256))) << "patch " << p << " channel " << ch;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 60);
}

TEST(camera_simulated, settings_are_validated_against_eos20d_limits) {
  Rig rig;
  cam::CameraSettings s;
  s.iso = 400;
  s.shutter_s = 1.0 / 60;
  s.aperture_f = 8;
  rig.camera->configure(s).get();
  EXPECT_EQ(rig.camera->model_settings().iso, 400);
  EXPECT_NEAR(rig.camera->model_settings().shutter_s, 1.0 / 60, 1e-9);
  EXPECT_EQ(rig.camera->settings().aperture_f, 8.0);

  cam::CameraSettings bad;
  bad.iso = 250;
  try {
    rig.camera->configure(bad).get();
    FAIL();
  } catch (const colorlab::Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::bad_parameter);
    EXPECT_NE(e.hint().find("1600"), std::string::npos);  // lists what is allowed
  }
  cam::CameraSettings genicam;
  genicam.exposure_us = 1000;
  try {
    rig.camera->configure(genicam).get();
    FAIL();
  } catch (const colorlab::Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::unsupported);
  }
  EXPECT_EQ(rig.camera->model_settings().iso, 400);  // a rejected request changes nothing
}

TEST(camera_simulated, capture_timeout_mid_series_is_partial_and_recoverable) {
  Rig rig;
  rig.camera->inject_fault(cam::CameraFault::capture_timeout, 2);
  auto report = capture_n(*rig.camera, 5);
  EXPECT_FALSE(report.complete());
  EXPECT_EQ(report.delivered, 2U);
  ASSERT_TRUE(report.error);
  EXPECT_EQ(report.error->cls(), ErrorClass::timeout);
  EXPECT_TRUE(report.error->info().retryable);
  EXPECT_EQ(rig.camera->state(), cam::CameraState::ready);
  EXPECT_TRUE(capture_n(*rig.camera, 2).complete());
}

TEST(camera_simulated, busy_camera_is_a_typed_conflict) {
  Rig rig;
  rig.camera->inject_fault(cam::CameraFault::busy, 1);
  auto report = capture_n(*rig.camera, 3);
  EXPECT_FALSE(report.complete());
  EXPECT_EQ(report.delivered, 1U);
  ASSERT_TRUE(report.error);
  EXPECT_EQ(report.error->cls(), ErrorClass::conflict);
  EXPECT_FALSE(report.error->hint().empty());
  EXPECT_EQ(rig.camera->state(), cam::CameraState::ready);
}

TEST(camera_simulated, disconnect_mid_series_needs_a_reconnect) {
  Rig rig;
  rig.camera->inject_fault(cam::CameraFault::disconnect, 3);
  auto report = capture_n(*rig.camera, 6);
  EXPECT_FALSE(report.complete());
  EXPECT_EQ(report.delivered, 3U);
  ASSERT_TRUE(report.error);
  EXPECT_EQ(report.error->cls(), ErrorClass::no_comms);
  EXPECT_EQ(rig.camera->state(), cam::CameraState::disconnected);

  auto refused = capture_n(*rig.camera, 1);
  EXPECT_EQ(refused.delivered, 0U);
  ASSERT_TRUE(refused.error);
  EXPECT_EQ(refused.error->cls(), ErrorClass::no_comms);

  // The error carries the transcript of what led to it.
  const auto& lines = report.error->info().transcript;
  ASSERT_FALSE(lines.empty());
  EXPECT_NE(lines.back().find("capture failed"), std::string::npos) << lines.back();
  EXPECT_TRUE(std::any_of(lines.begin(), lines.end(),
                          [](const std::string& l) { return l.find("frame 2 captured") != std::string::npos; }));

  rig.camera->reconnect(3, std::chrono::milliseconds(1)).get();
  EXPECT_EQ(rig.camera->state(), cam::CameraState::ready);
  EXPECT_EQ(rig.camera->identity().serial, "SIM20D0001");
  EXPECT_TRUE(capture_n(*rig.camera, 2).complete());
}

TEST(camera_simulated, a_second_series_while_one_runs_is_refused_not_queued) {
  Rig rig(std::chrono::milliseconds(30));
  std::promise<void> first_frame;
  auto first = rig.camera->capture(4, [&, once = true](const cam::RawImage&) mutable {
    if (once) first_frame.set_value();
    once = false;
  });
  first_frame.get_future().wait();
  EXPECT_EQ(rig.camera->state(), cam::CameraState::busy);
  auto second = rig.camera->capture(1, [](const cam::RawImage&) {}).get();  // answered at once
  ASSERT_TRUE(second.error);
  EXPECT_EQ(second.error->cls(), ErrorClass::conflict);
  EXPECT_EQ(second.delivered, 0U);
  cam::CameraSettings s;
  s.iso = 200;
  try {
    rig.camera->configure(s).get();
    FAIL() << "configure during a series must be refused";
  } catch (const colorlab::Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::conflict);
  }
  EXPECT_TRUE(first.get().complete());
}

TEST(camera_simulated, sink_failure_stops_the_series_and_is_reported) {
  Rig rig;
  auto report = rig.camera
                    ->capture(5,
                              [](const cam::RawImage& img) {
                                if (img.frame_index == 2) {
                                  throw colorlab::Error(ErrorClass::io_error, "disk full", "free space");
                                }
                              })
                    .get();
  EXPECT_FALSE(report.complete());
  EXPECT_EQ(report.delivered, 2U);
  ASSERT_TRUE(report.error);
  EXPECT_EQ(report.error->cls(), ErrorClass::io_error);
  EXPECT_EQ(rig.camera->state(), cam::CameraState::ready);
}

TEST(camera_simulated, next_frame_is_captured_while_the_sink_works) {
  Rig rig;
  bool overlapped = false;
  auto report = rig.camera
                    ->capture(3,
                              [&](const cam::RawImage& img) {
                                if (img.frame_index != 0) return;
                                // Hold frame 0 until shot 1 has been rendered (or give up after 10 s):
                                // only a pipelined camera gets there.
                                const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
                                while (rig.camera->frames_rendered() < 2 && std::chrono::steady_clock::now() < deadline) {
                                  std::this_thread::sleep_for(std::chrono::milliseconds(1));
                                }
                                overlapped = rig.camera->frames_rendered() >= 2;
                              })
                    .get();
  EXPECT_TRUE(report.complete());
  EXPECT_TRUE(overlapped);
}

TEST(camera_simulated, callback_api_returns_before_the_series_ends) {
  Rig rig;
  std::promise<void> release;
  auto released = release.get_future().share();
  std::promise<cam::CaptureReport> done;
  rig.camera->capture(
      2, [released](const cam::RawImage&) { released.wait_for(std::chrono::seconds(10)); },
      [&](cam::CaptureReport r) { done.set_value(std::move(r)); });
  // Reaching this line while the sink is still blocked shows capture() did not block the caller.
  release.set_value();
  auto report = done.get_future().get();
  EXPECT_TRUE(report.complete());
}

TEST(camera_simulated, raw_plus_jpeg_pairs_the_processed_image_by_basename) {
  Rig rig;
  cam::CameraSettings s;
  s.image_format = cam::ImageFormat::raw_and_jpeg;
  rig.camera->configure(s).get();
  auto report = capture_n(*rig.camera, 2);
  ASSERT_TRUE(report.complete()) << (report.error ? report.error->what() : "");
  ASSERT_EQ(report.saved_files.size(), 4U);
  for (std::size_t i = 0; i < 4; i += 2) {
    EXPECT_EQ(report.saved_files[i].extension(), ".DNG");
    EXPECT_EQ(report.saved_files[i].stem(), report.saved_files[i + 1].stem());
    EXPECT_TRUE(report.saved_files[i + 1].extension() == ".JPG" || report.saved_files[i + 1].extension() == ".TIF");
    EXPECT_GT(fs::file_size(report.saved_files[i + 1]), 1000U);
  }
}
