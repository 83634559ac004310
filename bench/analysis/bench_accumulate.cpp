// Streaming accumulation of 3504×2336 16-bit frames (Canon 20D size) against a STREAM-like triad in the same run.
// Bytes per pixel and frame: 2 read (frame) + 4 read/write (u32 sum) + 8 read/write (u64 sum of squares) = 26;
// the triad moves 24 bytes per element (STREAM's convention, without write-allocate).
#include <benchmark/benchmark.h>

#include <cstdint>
#include <random>
#include <vector>

#include "colorlab/analysis/frame_accumulator.hpp"

namespace {

constexpr std::size_t kW = 3504, kH = 2336, kPixels = kW * kH;

const std::vector<std::vector<std::uint16_t>>& frames() {
  static const auto f = [] {
    std::vector<std::vector<std::uint16_t>> v(4, std::vector<std::uint16_t>(kPixels));
    std::mt19937 rng(1);
    for (auto& fr : v)
      for (auto& p : fr) p = static_cast<std::uint16_t>(rng() & 0x0fff);
    return v;
  }();
  return f;
}

void BM_Accumulate(benchmark::State& state) {
  const auto& f = frames();
  colorlab::analysis::FrameAccumulator acc(kW, kH);
  std::size_t i = 0;
  for (auto _ : state) {
    acc.add(f[i++ % f.size()]);
    if (acc.frames() == 60000) acc.reset();
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(kPixels) * 26);
  state.counters["frames_per_s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Accumulate)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();

void BM_StreamTriad(benchmark::State& state) {
  const std::size_t n = 20'000'000;  // 3 × 160 MB: far beyond any cache
  std::vector<double> a(n, 1.0), b(n, 2.0), c(n, 3.0);
  const double s = 3.0;
  for (auto _ : state) {
    double* __restrict pa = a.data();
    const double* __restrict pb = b.data();
    const double* __restrict pc = c.data();
    for (std::size_t i = 0; i < n; ++i) pa[i] = pb[i] + s * pc[i];
    benchmark::DoNotOptimize(pa);
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(n) * 24);
}
BENCHMARK(BM_StreamTriad)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
