// The production path at full 20D size: SimulatedCamera renders and writes a 3504x2336 DNG per
// frame (plus a simulated camera time), the decode thread runs LibRaw and the analysis frame
// accumulator. Compared with the same work done capture-then-process on one thread.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <thread>

#include "colorlab/analysis/frame_accumulator.hpp"
#include "colorlab/drivers/camera/raw_decoder.hpp"
#include "colorlab/drivers/camera/simulated_camera.hpp"
#include "colorlab/sim/camera/dng.hpp"

namespace cam = colorlab::drivers::camera;
namespace simcam = colorlab::sim::camera;
namespace fs = std::filesystem;
using namespace std::chrono;

namespace {

constexpr std::size_t kFrames = 6;

std::shared_ptr<simcam::CameraModel> full_size_model() {
  static auto model = [] {
    colorlab::sim::SceneConfig scene;
    scene.force_synthetic_chart = true;
    scene.lamps_on_at_start = {colorlab::sim::Lamp::d65};
    auto s = std::make_shared<colorlab::sim::Scene>(scene, std::make_shared<colorlab::sim::SimClock>());
    simcam::CameraConfig cfg;  // 3504 x 2336
    cfg.threads = 1;           // one core renders, the other decodes
    return std::make_shared<simcam::CameraModel>(s, cfg);
  }();
  return model;
}

fs::path bench_dir() {
  auto d = fs::temp_directory_path() / ("colorlab-bench-camera-" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

void counters(benchmark::State& state, double capture_ms, double decode_ms, double frame_ms) {
  state.counters["capture_ms"] = capture_ms;
  state.counters["decode_ms"] = decode_ms;
  state.counters["frame_ms"] = frame_ms;
  state.counters["vs_max"] = frame_ms / std::max(capture_ms, decode_ms);
  state.counters["vs_sum"] = frame_ms / (capture_ms + decode_ms);
}

// Arg: simulated camera time per frame in ms (exposure + USB transfer on a real body).
void BM_camera_simulated_pipeline(benchmark::State& state) {
  const auto dir = bench_dir();
  auto model = full_size_model();
  cam::SimulatedCameraOptions o;
  o.model = model;
  o.capture_dir = dir;
  o.keep_files = false;
  o.extra_capture_time = milliseconds(state.range(0));
  cam::SimulatedCamera camera(o);
  camera.connect().get();
  colorlab::analysis::FrameAccumulator acc(static_cast<std::size_t>(model->width()),
                                           static_cast<std::size_t>(model->height()));
  cam::CaptureReport report;
  for (auto _ : state) {
    acc.reset();
    report = camera.capture(kFrames, [&](const cam::RawImage& img) { acc.add(img.contiguous()); }).get();
    if (!report.complete()) state.SkipWithError(report.error ? report.error->what() : "incomplete");
  }
  const double n = kFrames;
  counters(state, duration<double, std::milli>(report.capture_time).count() / n,
           duration<double, std::milli>(report.decode_time).count() / n,
           duration<double, std::milli>(report.wall_time).count() / n);
  fs::remove_all(dir);
}

void BM_camera_simulated_sequential(benchmark::State& state) {
  const auto dir = bench_dir();
  auto model = full_size_model();
  const auto extra = milliseconds(state.range(0));
  colorlab::analysis::FrameAccumulator acc(static_cast<std::size_t>(model->width()),
                                           static_cast<std::size_t>(model->height()));
  cam::RawDecoder decoder;
  double capture_ms = 0, decode_ms = 0, wall_ms = 0;
  std::uint64_t shot = 0;
  for (auto _ : state) {
    acc.reset();
    capture_ms = decode_ms = 0;
    const auto start = steady_clock::now();
    for (std::size_t i = 0; i < kFrames; ++i) {
      const auto t0 = steady_clock::now();
      const auto frame = model->render({}, shot++);
      std::this_thread::sleep_for(extra);
      const auto path = dir / "IMG.DNG";
      simcam::write_dng(path, frame, {});
      std::ifstream in(path, std::ios::binary);
      const std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
      const auto t1 = steady_clock::now();
      acc.add(decoder.decode_buffer(bytes, "IMG.DNG").contiguous());
      const auto t2 = steady_clock::now();
      capture_ms += duration<double, std::milli>(t1 - t0).count();
      decode_ms += duration<double, std::milli>(t2 - t1).count();
    }
    wall_ms = duration<double, std::milli>(steady_clock::now() - start).count();
  }
  counters(state, capture_ms / kFrames, decode_ms / kFrames, wall_ms / kFrames);
  fs::remove_all(dir);
}

}  // namespace

BENCHMARK(BM_camera_simulated_pipeline)->Arg(0)->Arg(100)->Arg(300)->Iterations(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_camera_simulated_sequential)->Arg(0)->Arg(100)->Arg(300)->Iterations(2)->Unit(benchmark::kMillisecond)->UseRealTime();

namespace {

// The decode stage alone on one full-size DNG: LibRaw from a file (page cache) and from memory
// (the tethered path: bytes straight from the USB download).
void BM_camera_decode_dng(benchmark::State& state) {
  const auto dir = bench_dir();
  const auto path = dir / "IMG_DECODE.DNG";
  simcam::write_dng(path, full_size_model()->render({}, 0), {});
  std::ifstream in(path, std::ios::binary);
  const std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  cam::RawDecoder decoder;
  for (auto _ : state) {
    const auto img = state.range(0) == 0 ? decoder.decode_file(path) : decoder.decode_buffer(bytes, "IMG_DECODE.DNG");
    benchmark::DoNotOptimize(img.pixels);
  }
  state.SetLabel(state.range(0) == 0 ? "file" : "memory");
  fs::remove_all(dir);
}

}  // namespace

BENCHMARK(BM_camera_decode_dng)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Repetitions(3)->ReportAggregatesOnly(true);
