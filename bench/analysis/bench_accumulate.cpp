// Streaming accumulation of 3504×2336 16-bit frames (Canon 20D size) against a STREAM-like triad, both on one and on
// two threads, in the same binary run (run with --benchmark_repetitions and --benchmark_enable_random_interleaving
// so the four cases alternate).
//
// Bytes are counted the same way on both sides: every byte that crosses the memory bus, write-allocate included.
// - Accumulator, per pixel and frame: 2 read (frame) + 4 read + 4 written (u32 sum) + 8 read + 8 written (u64 sum of
//   squares) = 26. Its stores go to lines it has just read, so they cost no write-allocate read.
// - Triad a = b + s·c, per element: 8 read (b) + 8 read (c) + 8 read (a's line fetched for the store: write-allocate)
//   + 8 written (a) = 32. (STREAM's own convention counts 24 and leaves out the write-allocate read.)
// Two threads split each frame (by rows: two accumulators over the top and the bottom half, the same code) and the
// triad's arrays in halves; the threads are started per iteration on both sides alike.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <random>
#include <span>
#include <thread>
#include <vector>

#include "colorlab/analysis/frame_accumulator.hpp"

namespace {

constexpr std::size_t kW = 3504, kH = 2336, kPixels = kW * kH;
constexpr int64_t kAccumulatorBytesPerPixel = 26;
constexpr int64_t kTriadBytesPerElement = 32;  // with write-allocate, as the accumulator is counted

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

// Runs part(0..n-1) on n threads (n = 1: on the calling thread).
template <class F>
void on_threads(int n, F part) {
  if (n == 1) {
    part(0);
    return;
  }
  std::vector<std::thread> t;
  for (int i = 1; i < n; ++i) t.emplace_back(part, i);
  part(0);
  for (auto& th : t) th.join();
}

void BM_Accumulate(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  const auto& f = frames();
  const std::size_t rows = kH / static_cast<std::size_t>(threads);
  std::vector<colorlab::analysis::FrameAccumulator> acc;
  for (int i = 0; i < threads; ++i) acc.emplace_back(kW, rows);
  std::size_t k = 0;
  for (auto _ : state) {
    std::span<const std::uint16_t> frame(f[k++ % f.size()]);
    on_threads(threads, [&](int i) {
      auto& a = acc[static_cast<std::size_t>(i)];
      a.add(frame.subspan(static_cast<std::size_t>(i) * rows * kW, rows * kW));
      if (a.frames() == 60000) a.reset();
    });
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(kPixels) * kAccumulatorBytesPerPixel);
  state.counters["frames_per_s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Accumulate)->ArgName("threads")->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();

void BM_StreamTriad(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  const std::size_t n = 20'000'000;  // 3 × 160 MB: far beyond any cache
  std::vector<double> a(n, 1.0), b(n, 2.0), c(n, 3.0);
  const double s = 3.0;
  const std::size_t per = n / static_cast<std::size_t>(threads);
  for (auto _ : state) {
    on_threads(threads, [&](int t) {
      double* __restrict pa = a.data() + static_cast<std::size_t>(t) * per;
      const double* __restrict pb = b.data() + static_cast<std::size_t>(t) * per;
      const double* __restrict pc = c.data() + static_cast<std::size_t>(t) * per;
      for (std::size_t i = 0; i < per; ++i) pa[i] = pb[i] + s * pc[i];
    });
    benchmark::DoNotOptimize(a.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(per) * threads * kTriadBytesPerElement);
}
BENCHMARK(BM_StreamTriad)->ArgName("threads")->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
