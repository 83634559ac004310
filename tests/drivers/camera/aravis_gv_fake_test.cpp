// The Aravis driver against Aravis's GigE Vision fake camera on loopback: the real GVCP/GVSP code
// path, our derived 12-bit Bayer GenICam description and a fill whose every count is known.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "colorlab/drivers/camera/aravis_camera.hpp"
#include "colorlab/sim/aravis/gv_fake_camera.hpp"
#include "colorlab/sim/aravis/scene_fill.hpp"
#include "sim_fixture.hpp"

namespace cam = colorlab::drivers::camera;
namespace gv = colorlab::sim::aravis;
using colorlab::ErrorClass;

namespace {

// GVCP has one well-known port per address, so fakes from parallel test processes take turns.
std::unique_ptr<gv::GvFakeCamera> start_fake(gv::GvFakeOptions options = {}) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  for (;;) {
    try {
      return std::make_unique<gv::GvFakeCamera>(options);
    } catch (const colorlab::Error& e) {
      if (e.cls() != ErrorClass::conflict || std::chrono::steady_clock::now() > deadline) throw;
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
  }
}

cam::AravisOptions small_roi() {
  cam::AravisOptions o;
  o.device_id = "127.0.0.1";
  o.region = cam::Region{100, 200, 64, 48};  // even offsets keep the RGGB phase
  o.frame_rate_hz = 200;
  o.frame_timeout = std::chrono::milliseconds(1000);
  return o;
}

}  // namespace

TEST(camera_aravis, opens_gv_fake_and_reads_identity_and_limits) {
  auto fake = start_fake();
  cam::AravisCamera camera(small_roi());
  camera.connect().get();
  EXPECT_EQ(camera.state(), cam::CameraState::ready);
  const auto id = camera.identity();
  EXPECT_EQ(id.kind, cam::CameraKind::genicam);
  EXPECT_EQ(id.make, "Aravis");
  EXPECT_EQ(id.serial, fake->serial());
  const auto limits = camera.limits();
  ASSERT_TRUE(limits.exposure_us.has_value());
  EXPECT_LE(limits.exposure_us->min, 100.0);
  EXPECT_GE(limits.exposure_us->max, 1e6);
  EXPECT_NE(std::find(limits.pixel_formats.begin(), limits.pixel_formats.end(), cam::PixelFormat::bayer_rg12),
            limits.pixel_formats.end());
  EXPECT_NE(std::find(limits.pixel_formats.begin(), limits.pixel_formats.end(), cam::PixelFormat::mono16),
            limits.pixel_formats.end());
  EXPECT_TRUE(limits.iso.empty());  // GenICam cameras have no ISO
}

TEST(camera_aravis, acquires_exact_bayer12_frames_with_software_trigger) {
  auto fake = start_fake();
  cam::AravisCamera camera(small_roi());
  camera.connect().get();
  cam::CameraSettings s;
  s.pixel_format = cam::PixelFormat::bayer_rg12;
  s.exposure_us = 5000;
  s.gain = 0;
  camera.configure(s).get();

  std::size_t frames = 0;
  std::size_t wrong = 0;
  std::vector<std::uint64_t> indices;
  auto report = camera
                    .capture(5,
                             [&](const cam::RawImage& img) {
                               ++frames;
                               indices.push_back(img.frame_index);
                               EXPECT_EQ(img.width, 64U);
                               EXPECT_EQ(img.height, 48U);
                               EXPECT_EQ(img.white_level, 4095);
                               EXPECT_EQ(img.cfa, cam::CfaPattern::rggb());
                               for (std::size_t y = 0; y < img.height; ++y) {
                                 for (std::size_t x = 0; x < img.width; ++x) {
                                   wrong += img.at(x, y) != gv::test_pattern_value(int(x) + 100, int(y) + 200);
                                 }
                               }
                             })
                    .get();
  EXPECT_TRUE(report.complete()) << (report.error ? report.error->what() : "");
  EXPECT_EQ(report.delivered, 5U);
  EXPECT_EQ(frames, 5U);
  EXPECT_EQ(wrong, 0U);
  EXPECT_EQ(indices, (std::vector<std::uint64_t>{0, 1, 2, 3, 4}));  // series positions, not camera frame ids
  EXPECT_EQ(camera.state(), cam::CameraState::ready);
}

TEST(camera_aravis, odd_roi_offset_shifts_the_cfa_phase) {
  auto fake = start_fake();
  auto o = small_roi();
  o.region = cam::Region{101, 200, 32, 16};
  cam::AravisCamera camera(o);
  camera.connect().get();
  cam::CameraSettings s;
  s.pixel_format = cam::PixelFormat::bayer_rg16;
  camera.configure(s).get();
  cam::CfaPattern seen;
  auto report = camera.capture(1, [&](const cam::RawImage& img) { seen = img.cfa; }).get();
  ASSERT_TRUE(report.complete()) << (report.error ? report.error->what() : "");
  EXPECT_EQ(seen.name(), "GRBG");
}

TEST(camera_aravis, rejects_settings_outside_limits_with_typed_errors) {
  auto fake = start_fake();
  cam::AravisCamera camera(small_roi());
  camera.connect().get();
  cam::CameraSettings too_long;
  too_long.exposure_us = 1e9;
  try {
    camera.configure(too_long).get();
    FAIL() << "expected bad_parameter";
  } catch (const colorlab::Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::bad_parameter);
    EXPECT_FALSE(e.hint().empty());
  }
  cam::CameraSettings iso;
  iso.iso = 100;
  try {
    camera.configure(iso).get();
    FAIL() << "expected unsupported";
  } catch (const colorlab::Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::unsupported);
  }
  EXPECT_EQ(camera.state(), cam::CameraState::ready);
}

TEST(camera_aravis, stalled_camera_ends_series_as_partial_timeout) {
  auto fake = start_fake();
  auto o = small_roi();
  o.frame_timeout = std::chrono::milliseconds(300);
  o.max_retries_per_frame = 1;
  cam::AravisCamera camera(o);
  camera.connect().get();
  cam::CameraSettings s;
  s.pixel_format = cam::PixelFormat::bayer_rg12;
  camera.configure(s).get();
  std::size_t seen = 0;
  auto report = camera
                    .capture(6,
                             [&](const cam::RawImage&) {
                               if (++seen == 2) fake->stall();
                             })
                    .get();
  EXPECT_FALSE(report.complete());
  ASSERT_TRUE(report.error.has_value());
  EXPECT_EQ(report.error->cls(), ErrorClass::timeout);
  EXPECT_GE(report.delivered, 2U);
  EXPECT_LT(report.delivered, 6U);
  EXPECT_EQ(camera.state(), cam::CameraState::ready);  // a timeout leaves the camera usable

  // A new series restarts acquisition, so the camera recovers without reconnecting.
  auto again = camera.capture(2, [](const cam::RawImage&) {}).get();
  EXPECT_TRUE(again.complete()) << (again.error ? again.error->what() : "");
}

TEST(camera_aravis, camera_vanishing_mid_series_is_a_typed_partial_failure) {
  auto fake = start_fake();
  auto o = small_roi();
  o.frame_timeout = std::chrono::milliseconds(300);
  o.max_retries_per_frame = 1;
  cam::AravisCamera camera(o);
  camera.connect().get();
  cam::CameraSettings s;
  s.pixel_format = cam::PixelFormat::mono16;
  camera.configure(s).get();
  std::size_t seen = 0;
  auto report = camera
                    .capture(8,
                             [&](const cam::RawImage& img) {
                               EXPECT_FALSE(img.cfa.is_mosaic());
                               if (++seen == 3) fake->unplug();  // the camera disappears from the network
                             })
                    .get();
  EXPECT_FALSE(report.complete());
  ASSERT_TRUE(report.error.has_value());
  EXPECT_TRUE(report.error->cls() == ErrorClass::timeout || report.error->cls() == ErrorClass::no_comms)
      << report.error->what();
  EXPECT_GE(report.delivered, 3U);
  EXPECT_LT(report.delivered, 8U);
}

TEST(camera_aravis, open_without_camera_is_a_typed_error) {
  cam::AravisOptions o;
  o.device_id = "192.0.2.1";  // TEST-NET-1: guaranteed not to answer
  cam::AravisCamera camera(o);
  try {
    camera.connect().get();
    FAIL() << "expected an error";
  } catch (const colorlab::Error& e) {
    EXPECT_TRUE(e.cls() == ErrorClass::no_comms || e.cls() == ErrorClass::not_found ||
                e.cls() == ErrorClass::timeout)
        << to_string(e.cls()) << ": " << e.what();
  }
  EXPECT_EQ(camera.state(), cam::CameraState::disconnected);
  auto report = camera.capture(1, [](const cam::RawImage&) {}).get();
  ASSERT_TRUE(report.error.has_value());
  EXPECT_EQ(report.error->cls(), ErrorClass::no_comms);
  EXPECT_EQ(report.delivered, 0U);
}

TEST(camera_aravis, scene_frames_average_to_the_scene_ground_truth) {
  auto model = cam::test::small_model(640, 428);
  auto fake = start_fake(gv::scene_camera_options(model, 4.0));
  // ROI: the bounding box of four neighbouring patches, on even coordinates (RGGB phase kept).
  const int patches[] = {44, 45, 54, 55};
  int x0 = 1 << 30, y0 = 1 << 30, x1 = 0, y1 = 0;
  for (int p : patches) {
    const auto r = model->patch_region(p);
    x0 = std::min(x0, r.x);
    y0 = std::min(y0, r.y);
    x1 = std::max(x1, r.x + r.width);
    y1 = std::max(y1, r.y + r.height);
  }
  x0 &= ~1;
  y0 &= ~1;
  const int w = (x1 - x0 + 1) & ~1, h = (y1 - y0 + 1) & ~1;
  auto o = small_roi();
  o.region = cam::Region{x0, y0, w, h};
  o.black_level = 256;  // the simulated sensor's offset, as a lab would configure it
  cam::AravisCamera camera(o);
  camera.connect().get();
  cam::CameraSettings s;
  s.pixel_format = cam::PixelFormat::bayer_rg12;
  s.exposure_us = 1e6 / 30;
  s.gain = 0;
  camera.configure(s).get();

  std::vector<double> sum(static_cast<std::size_t>(w * h), 0.0);
  const std::size_t n = 4;
  auto report = camera
                    .capture(n,
                             [&](const cam::RawImage& img) {
                               ASSERT_EQ(img.width, static_cast<std::size_t>(w));
                               EXPECT_EQ(img.black_at(0, 0), 256);
                               for (std::size_t y = 0; y < img.height; ++y) {
                                 for (std::size_t x = 0; x < img.width; ++x) sum[y * img.width + x] += img.at(x, y);
                               }
                             })
                    .get();
  ASSERT_TRUE(report.complete()) << (report.error ? report.error->what() : "");
  const auto truth = model->ground_truth(gv::model_settings_for(1e6 / 30, 0, 4.0));
  for (int p : patches) {
    const auto r = model->patch_region(p);
    for (int ch = 0; ch < 3; ++ch) {
      std::vector<double> v;  // inner half of the patch, median: clear of edges and dust
      for (int y = r.y + r.height / 4; y < r.y + 3 * r.height / 4; ++y) {
        for (int x = r.x + r.width / 4; x < r.x + 3 * r.width / 4; ++x) {
          if (colorlab::sim::camera::rggb_channel(x, y) == ch) {
            v.push_back(sum[static_cast<std::size_t>((y - y0) * w + (x - x0))] / n);
          }
        }
      }
      ASSERT_FALSE(v.empty());
      std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
      const double expected = truth[static_cast<std::size_t>(p)][static_cast<std::size_t>(ch)];
      EXPECT_NEAR(v[v.size() / 2], expected, std::max(4.0, 0.02 * (expected - 256))) << "patch " << p << " ch " << ch;
    }
  }
}

TEST(camera_aravis, reconnect_verifies_the_camera_is_the_same_body) {
  auto fake = start_fake();
  cam::AravisCamera camera(small_roi());
  camera.connect().get();
  cam::CameraSettings s;
  s.pixel_format = cam::PixelFormat::bayer_rg12;  // must survive the reconnect (the new fake starts in Mono8)
  camera.configure(s).get();
  fake->plug_in("CLGV0002");  // another body at the same address
  try {
    camera.reconnect(2, std::chrono::milliseconds(10)).get();
    FAIL() << "a different serial must not be accepted silently";
  } catch (const colorlab::Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::needs_operator) << e.what();
    EXPECT_NE(std::string(e.what()).find("CLGV0002"), std::string::npos);
  }
  EXPECT_EQ(camera.state(), cam::CameraState::disconnected);
  fake->plug_in("CLGV0001");  // the original body is back
  camera.reconnect(2, std::chrono::milliseconds(10)).get();
  EXPECT_EQ(camera.state(), cam::CameraState::ready);
  auto report = camera.capture(1, [](const cam::RawImage&) {}).get();
  EXPECT_TRUE(report.complete()) << report.delivered << "/" << report.requested << " " << (report.error ? report.error->what() : "no error");
}
