// Locating a ColorChecker SG and sampling its 140 patches in a 3504×2336 frame (issue 14: ≤ 200 ms): the simulated
// camera's raw mosaic (per CFA colour) and its developed 16-bit RGB, the chart at a seeded pose with distortion.
#include <benchmark/benchmark.h>

#include <memory>

#include "colorlab/analysis/chart_locate.hpp"
#include "colorlab/sim/camera/camera_model.hpp"
#include "colorlab/sim/camera/processed.hpp"

namespace {

namespace ca = colorlab::analysis;
namespace cam = colorlab::sim::camera;

struct Frames {
  cam::RawFrame raw;
  cam::RgbImage rgb;
  ca::LensCalibration lens;
};

const Frames& frames() {
  static const Frames f = [] {
    colorlab::sim::SceneConfig sc;
    sc.seed = 4;
    sc.force_synthetic_chart = false;  // X-Rite's spectra when the shared data set is present
    sc.lamps_on_at_start = {colorlab::sim::Lamp::d65};
    auto scene = std::make_shared<colorlab::sim::Scene>(sc, std::make_shared<colorlab::sim::SimClock>());
    cam::CameraConfig cc;  // 3504 × 2336
    cc.chart_height_fraction = 0.7;
    cc.pose = cam::random_chart_pose(7);
    const cam::CameraModel camera(scene, cc);
    Frames out;
    out.raw = camera.render({}, 1);
    out.rgb = cam::develop(out.raw, camera);
    const auto l = camera.lens();
    out.lens = {l.fx, l.fy, l.cx, l.cy, l.k1, l.k2, 0, 0, 0};
    return out;
  }();
  return f;
}

void BM_LocateSampleRaw(benchmark::State& state) {
  const Frames& f = frames();
  ca::PhotoView v{f.raw.pixels.data(), f.raw.width, f.raw.height, 1, ca::SampleType::u16};
  v.bit_depth = 12;
  v.black_level = f.raw.black_level;
  v.cfa = ca::CfaPattern::rggb;
  ca::LocateOptions o;
  o.lens = f.lens;
  for (auto _ : state) benchmark::DoNotOptimize(ca::locate_chart(v, ca::ChartType::sg140, o));
}
BENCHMARK(BM_LocateSampleRaw)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_LocateSampleRgb16(benchmark::State& state) {
  const Frames& f = frames();
  ca::PhotoView v{f.rgb.rgb.data(), f.rgb.width, f.rgb.height, 3, ca::SampleType::u16};
  ca::LocateOptions o;
  o.lens = f.lens;
  for (auto _ : state) benchmark::DoNotOptimize(ca::locate_chart(v, ca::ChartType::sg140, o));
}
BENCHMARK(BM_LocateSampleRgb16)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
