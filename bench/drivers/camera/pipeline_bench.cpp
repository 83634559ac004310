// Throughput of the camera pipeline: with capture and decode overlapped, a series takes
// max(capture, decode) per frame, not their sum. Capture is modelled as waiting (a camera
// exposing and transferring), decode as CPU work (LibRaw + accumulation), so the measurement
// also shows the decode thread using the CPU while the capture thread waits.
//
//   bench_camera_pipeline --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <chrono>
#include <thread>

#include "colorlab/drivers/camera/frame_pipeline.hpp"

namespace cam = colorlab::drivers::camera;
using namespace std::chrono;

namespace {

void spin_for(microseconds d) {
  const auto end = steady_clock::now() + d;
  volatile std::uint64_t x = 0;
  while (steady_clock::now() < end) x = x + 1;
}

constexpr std::size_t kFrames = 12;

void report(benchmark::State& state, double capture_ms, double decode_ms, double per_frame_ms) {
  state.counters["capture_ms"] = capture_ms;
  state.counters["decode_ms"] = decode_ms;
  state.counters["frame_ms"] = per_frame_ms;
  state.counters["vs_max"] = per_frame_ms / std::max(capture_ms, decode_ms);  // 1.0 = ideal pipeline
  state.counters["vs_sum"] = per_frame_ms / (capture_ms + decode_ms);         // 1.0 = no overlap
}

// Args: capture ms, decode ms per frame.
void BM_camera_pipeline(benchmark::State& state) {
  const auto capture = milliseconds(state.range(0));
  const auto decode = milliseconds(state.range(1));
  cam::FramePipeline<int> pipeline(2);
  cam::PipelineRun last;
  for (auto _ : state) {
    last = pipeline.run(
        kFrames,
        [&](std::size_t) {
          std::this_thread::sleep_for(capture);
          return 0;
        },
        [&](int&&, std::size_t) { spin_for(decode); });
  }
  const double n = static_cast<double>(kFrames);
  report(state, duration<double, std::milli>(last.produce_time).count() / n,
         duration<double, std::milli>(last.consume_time).count() / n,
         duration<double, std::milli>(last.wall_time).count() / n);
}

// The same work capture-then-process, as a baseline.
void BM_camera_sequential(benchmark::State& state) {
  const auto capture = milliseconds(state.range(0));
  const auto decode = milliseconds(state.range(1));
  double wall = 0, captured = 0, decoded = 0;
  for (auto _ : state) {
    captured = decoded = 0;
    const auto t0 = steady_clock::now();
    for (std::size_t i = 0; i < kFrames; ++i) {
      const auto a = steady_clock::now();
      std::this_thread::sleep_for(capture);
      const auto b = steady_clock::now();
      spin_for(decode);
      captured += duration<double, std::milli>(b - a).count();
      decoded += duration<double, std::milli>(steady_clock::now() - b).count();
    }
    wall = duration<double, std::milli>(steady_clock::now() - t0).count();
  }
  report(state, captured / kFrames, decoded / kFrames, wall / kFrames);
}

void stage_times(benchmark::internal::Benchmark* b) {
  b->Args({40, 10})->Args({20, 20})->Args({10, 40})->Args({30, 15})->Unit(benchmark::kMillisecond)->Iterations(3);
}

}  // namespace

BENCHMARK(BM_camera_pipeline)->Apply(stage_times)->UseRealTime();
BENCHMARK(BM_camera_sequential)->Apply(stage_times)->UseRealTime();

BENCHMARK_MAIN();
