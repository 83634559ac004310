// 140 robust patch values (median, then mean within ±k) on a 16-bit 3504×2336 frame, 40×40-pixel regions.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "colorlab/analysis/chart_io.hpp"
#include "colorlab/analysis/patch_stats.hpp"

namespace {

void BM_RobustPatches140(benchmark::State& state) {
  constexpr std::size_t w = 3504, h = 2336;
  std::vector<float> img(w * h);
  std::mt19937 rng(2);
  std::normal_distribution<float> nd(0, 40);
  for (auto& p : img) p = 20000 + nd(rng);
  colorlab::analysis::ImageView v{img.data(), w, h, w};
  std::vector<colorlab::analysis::Rect> rects;
  for (int n = 1; n <= 140; ++n) {
    int number = colorlab::analysis::sg_patch_number(colorlab::analysis::sg_patch_id(n));
    std::size_t col = static_cast<std::size_t>((number - 1) % 14), row = static_cast<std::size_t>((number - 1) / 14);
    rects.push_back({200 + col * 220, 100 + row * 220, 40, 40});
  }
  colorlab::analysis::RobustOptions opt;
  opt.bit_depth = 16;
  for (auto _ : state)
    for (const auto& r : rects) benchmark::DoNotOptimize(colorlab::analysis::robust_patch_value(v, r, opt));
}
BENCHMARK(BM_RobustPatches140)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
