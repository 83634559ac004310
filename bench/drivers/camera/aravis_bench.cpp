// Full-frame GenICam acquisition over loopback: the Aravis driver against the GigE Vision fake
// serving the scene at 3504 x 2336 BayerRG12 (16.4 MB per frame), software-triggered, frames
// streaming into the analysis accumulator.
//
//   bench_camera_aravis --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include "colorlab/analysis/frame_accumulator.hpp"
#include "colorlab/drivers/camera/aravis_camera.hpp"
#include "colorlab/sim/aravis/scene_fill.hpp"

namespace cam = colorlab::drivers::camera;
namespace gv = colorlab::sim::aravis;
using namespace std::chrono;

namespace {

void BM_camera_aravis_full_frame(benchmark::State& state) {
  colorlab::sim::SceneConfig scene;
  scene.force_synthetic_chart = true;
  scene.lamps_on_at_start = {colorlab::sim::Lamp::d65};
  auto s = std::make_shared<colorlab::sim::Scene>(scene, std::make_shared<colorlab::sim::SimClock>());
  colorlab::sim::camera::CameraConfig cfg;  // 3504 x 2336
  cfg.threads = 1;
  auto model = std::make_shared<colorlab::sim::camera::CameraModel>(s, cfg);
  gv::GvFakeCamera fake(gv::scene_camera_options(model));

  cam::AravisOptions o;
  o.device_id = fake.address();
  o.frame_timeout = milliseconds(5000);
  cam::AravisCamera camera(o);
  camera.connect().get();
  cam::CameraSettings settings;
  settings.pixel_format = cam::PixelFormat::bayer_rg12;
  settings.exposure_us = 1e6 / 30;
  camera.configure(settings).get();

  const std::size_t n = static_cast<std::size_t>(state.range(0));
  colorlab::analysis::FrameAccumulator acc(static_cast<std::size_t>(model->width()),
                                           static_cast<std::size_t>(model->height()));
  cam::CaptureReport report;
  for (auto _ : state) {
    acc.reset();
    report = camera.capture(n, [&](const cam::RawImage& img) { acc.add(img.contiguous()); }).get();
    if (!report.complete()) state.SkipWithError(report.error ? report.error->what() : "incomplete");
  }
  const double frames = static_cast<double>(n);
  const double frame_ms = duration<double, std::milli>(report.wall_time).count() / frames;
  state.counters["capture_ms"] = duration<double, std::milli>(report.capture_time).count() / frames;
  state.counters["decode_ms"] = duration<double, std::milli>(report.decode_time).count() / frames;
  state.counters["frame_ms"] = frame_ms;
  state.counters["fps"] = 1000.0 / frame_ms;
  state.counters["MB_per_s"] = 3504.0 * 2336 * 2 / 1e6 * 1000.0 / frame_ms;
  state.counters["failed_buffers"] = static_cast<double>(camera.failed_buffers());
}

}  // namespace

BENCHMARK(BM_camera_aravis_full_frame)->Arg(8)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
