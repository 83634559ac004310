// The daemon's view: a camera driven from an Asio event loop by co_await, with completions
// arriving on the loop's thread while the loop stays free to run other work.
#include <gtest/gtest.h>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/detached.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/use_awaitable.hpp>
#include <thread>

#include "colorlab/drivers/camera/asio_camera.hpp"
#include "colorlab/drivers/camera/simulated_camera.hpp"
#include "sim_fixture.hpp"

namespace asio = boost::asio;
namespace cam = colorlab::drivers::camera;
using colorlab::ErrorClass;

TEST(camera_asio, co_await_connect_configure_capture_on_the_loop_thread) {
  cam::test::TempDir dir;
  cam::SimulatedCameraOptions o;
  o.model = cam::test::small_model();
  o.capture_dir = dir.path();
  o.extra_capture_time = std::chrono::milliseconds(20);
  cam::SimulatedCamera camera(o);

  asio::io_context io;
  const auto loop_thread = std::this_thread::get_id();
  int ticks = 0;  // proves the loop ran other handlers while the capture was in flight
  bool finished = false;
  std::optional<cam::CaptureReport> report;
  std::optional<colorlab::Error> bad_setting;

  asio::co_spawn(
      io,
      [&]() -> asio::awaitable<void> {
        auto err = co_await cam::async_connect(camera, asio::use_awaitable);
        EXPECT_FALSE(err.has_value());
        EXPECT_EQ(std::this_thread::get_id(), loop_thread);
        cam::CameraSettings s;
        s.iso = 250;  // not an EOS 20D choice
        bad_setting = co_await cam::async_configure(camera, s, asio::use_awaitable);
        report = co_await cam::async_capture(
            camera, 4, [](const cam::RawImage&) {}, asio::use_awaitable);
        EXPECT_EQ(std::this_thread::get_id(), loop_thread);
        finished = true;
      },
      asio::detached);
  asio::co_spawn(
      io,
      [&]() -> asio::awaitable<void> {
        asio::steady_timer t(io);
        while (!finished) {
          t.expires_after(std::chrono::milliseconds(5));
          co_await t.async_wait(asio::use_awaitable);
          ++ticks;
        }
      },
      asio::detached);
  io.run();

  ASSERT_TRUE(report.has_value());
  EXPECT_TRUE(report->complete());
  EXPECT_EQ(report->delivered, 4U);
  ASSERT_TRUE(bad_setting.has_value());
  EXPECT_EQ(bad_setting->cls(), ErrorClass::bad_parameter);
  EXPECT_GT(ticks, 0);
}
