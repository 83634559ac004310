// The capture/decode pipeline: order, overlap of the two stages, bounded memory, and that a
// failure in either stage yields a partial (never a complete) series.
#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <thread>

#include "colorlab/drivers/camera/frame_pipeline.hpp"

namespace cam = colorlab::drivers::camera;

TEST(camera_pipeline, delivers_every_item_in_order) {
  cam::FramePipeline<int> p(2);
  std::vector<int> got;
  auto run = p.run(
      50, [](std::size_t i) { return static_cast<int>(i * 3); },
      [&](int&& v, std::size_t i) {
        EXPECT_EQ(v, static_cast<int>(i * 3));
        got.push_back(v);
      });
  EXPECT_TRUE(run.complete());
  EXPECT_EQ(run.produced, 50U);
  EXPECT_EQ(run.consumed, 50U);
  ASSERT_EQ(got.size(), 50U);
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i], static_cast<int>(i * 3));
}

TEST(camera_pipeline, producer_runs_ahead_by_at_most_the_queue_depth_plus_one) {
  cam::FramePipeline<int> p(2);
  std::atomic<int> produced{0};
  std::atomic<int> consumed{0};
  std::atomic<int> max_ahead{0};
  p.run(
      20,
      [&](std::size_t) {
        const int ahead = ++produced - consumed.load();
        max_ahead = std::max(max_ahead.load(), ahead);
        return 0;
      },
      [&](int&&, std::size_t) {
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
        ++consumed;
      });
  // Queue of 2, one item being consumed and one being produced.
  EXPECT_LE(max_ahead.load(), 4);
}

TEST(camera_pipeline, stages_overlap) {
  // Both stages wait on the other's signal: this only terminates if they run concurrently.
  cam::FramePipeline<int> p(2);
  std::atomic<int> consumer_started{0};
  auto run = p.run(
      3,
      [&](std::size_t i) {
        if (i == 2) {
          while (consumer_started.load() == 0) std::this_thread::yield();
        }
        return 0;
      },
      [&](int&&, std::size_t) { ++consumer_started; });
  EXPECT_TRUE(run.complete());
}

TEST(camera_pipeline, producer_failure_keeps_already_captured_frames_and_reports_partial) {
  cam::FramePipeline<int> p(2);
  std::vector<std::size_t> got;
  auto run = p.run(
      10,
      [](std::size_t i) {
        if (i == 4) throw std::runtime_error("camera gone");
        return 0;
      },
      [&](int&&, std::size_t i) { got.push_back(i); });
  EXPECT_FALSE(run.complete());
  EXPECT_EQ(run.produced, 4U);
  EXPECT_EQ(run.consumed, 4U);
  EXPECT_FALSE(run.error_in_consumer);
  EXPECT_EQ(got, (std::vector<std::size_t>{0, 1, 2, 3}));
  EXPECT_THROW(std::rethrow_exception(run.error), std::runtime_error);
}

TEST(camera_pipeline, consumer_failure_stops_the_producer) {
  cam::FramePipeline<int> p(1);
  std::atomic<int> produced{0};
  auto run = p.run(
      100, [&](std::size_t) { return ++produced; },
      [&](int&&, std::size_t i) {
        if (i == 3) throw std::runtime_error("disk full");
      });
  EXPECT_FALSE(run.complete());
  EXPECT_TRUE(run.error_in_consumer);
  EXPECT_EQ(run.consumed, 3U);
  EXPECT_LE(produced.load(), 3 + 1 + 2);  // item 3, the queue of 1, and the one in flight
}

TEST(camera_pipeline, is_reusable_for_many_series) {
  cam::FramePipeline<int> p(3);
  for (int s = 0; s < 20; ++s) {
    auto run = p.run(
        static_cast<std::size_t>(s), [](std::size_t) { return 1; }, [](int&&, std::size_t) {});
    EXPECT_TRUE(run.complete());
    EXPECT_EQ(run.consumed, static_cast<std::size_t>(s));
  }
}
