// The simulator must never be the bottleneck: one full 3504×2336 frame ≤ 100 ms, one DNG ≤ 30 ms.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>

#include "colorlab/sim/camera/camera_model.hpp"
#include "colorlab/sim/camera/dng.hpp"

namespace {

using namespace colorlab::sim;
using namespace colorlab::sim::camera;

std::shared_ptr<Scene> scene() {
  SceneConfig cfg;
  cfg.lamps_on_at_start = {Lamp::d65};
  static auto s = std::make_shared<Scene>(cfg, std::make_shared<SimClock>());
  return s;
}

const CameraModel& camera(int threads) {
  static CameraModel one(scene(), [] { CameraConfig c; c.threads = 1; return c; }());
  static CameraModel two(scene(), [] { CameraConfig c; c.threads = 2; return c; }());
  return threads == 1 ? one : two;
}

// Per-frame cost: noise on the cached noiseless image (what a capture loop pays).
void BM_RenderFullFrame(benchmark::State& state) {
  const auto& cam = camera(static_cast<int>(state.range(0)));
  RawFrame frame;
  cam.render_into(frame, {}, 0);  // builds the per-settings cache
  std::uint64_t i = 1;
  for (auto _ : state) {
    cam.render_into(frame, {}, i++);
    benchmark::DoNotOptimize(frame.pixels.data());
  }
  state.SetItemsProcessed(state.iterations() * cam.width() * cam.height());
}
BENCHMARK(BM_RenderFullFrame)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// One-off cost when settings or the lamps change: the noiseless image is rebuilt.
void BM_RebuildNoiselessImage(benchmark::State& state) {
  const auto& cam = camera(2);
  RawFrame frame;
  static double shutter = 1 / 30.0;  // never repeats across repetitions, so every iteration rebuilds
  for (auto _ : state) {
    shutter *= 1.0000001;  // new settings every iteration
    cam.render_into(frame, {4.0, shutter, 100}, 0);
    benchmark::DoNotOptimize(frame.pixels.data());
  }
}
BENCHMARK(BM_RebuildNoiselessImage)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_WriteDng(benchmark::State& state) {
  const auto& cam = camera(2);
  const RawFrame frame = cam.render({}, 1);
  DngMetadata meta;
  meta.color_matrix1 = cam.xyz_to_camera_d65();
  meta.as_shot_neutral = cam.as_shot_neutral();
  const auto dir = std::filesystem::temp_directory_path();
  const auto path = dir / ("bench_sim_" + std::to_string(::getpid()) + ".dng");
  for (auto _ : state) write_dng(path, frame, meta);
  std::filesystem::remove(path);
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(frame.pixels.size() * 2));
}
BENCHMARK(BM_WriteDng)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
