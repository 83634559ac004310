// All 26 polynomial term sets (dissertation 1–11, Hong/Cheung 3×n, root-polynomials 1–4) fitted to the 140-patch SG
// test vectors with leave-one-out CV (XYZ target, ΔE76 and ΔE00 per patch) — the same work as polyfit_numpy.py.
#include <benchmark/benchmark.h>

#include <iostream>

#include "colorlab/analysis/chart_io.hpp"
#include "colorlab/analysis/regression.hpp"
#include "colorlab/core/data_paths.hpp"

namespace {

void BM_AllSetsWithLoo(benchmark::State& state) {
  auto file = colorlab::paths::shared_data_file("testvec_sg140_canon20d_d50_argyll.csv");
  if (!file) {
    state.SkipWithError("testvec_sg140_canon20d_d50_argyll.csv not present (../shared/data)");
    return;
  }
  const auto chart = colorlab::analysis::read_chart(*file);
  const auto sets = colorlab::analysis::all_term_sets();
  colorlab::analysis::FitOptions o;
  o.input_scale = 1.0;
  for (auto _ : state)
    for (const auto& s : sets) benchmark::DoNotOptimize(colorlab::analysis::fit_report(s, chart, o, colorlab::analysis::CvSpec::loo()));
}
BENCHMARK(BM_AllSetsWithLoo)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
