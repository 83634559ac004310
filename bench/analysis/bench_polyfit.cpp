// All 26 polynomial term sets (dissertation 1–11, Hong/Cheung 3×n, root-polynomials 1–4) fitted to the 140-patch SG
// test vectors with leave-one-out CV (XYZ target, ΔE76 and ΔE00 per patch) — the same work as polyfit_numpy.py.
//
// Two ways to run it:
//   bench_analysis_polyfit [Google Benchmark flags]   this side alone;
//   bench_analysis_polyfit --serve [CSV]              the side-by-side harness's C++ half (polyfit_side_by_side.py):
//     reads a pass count N per line on stdin, runs N passes, each timed alone with steady_clock exactly as the numpy
//     half times its passes with perf_counter, and answers one line: "<rootpoly:3 LOO mean ΔE00> <ns> <ns> ...".
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>

#include "colorlab/analysis/chart_io.hpp"
#include "colorlab/analysis/regression.hpp"
#include "colorlab/core/data_paths.hpp"

namespace {

using colorlab::analysis::FitReport;

// One pass: every term set fitted with LOO. Returns rootpoly:3's LOO mean ΔE00 (set 25 of 26), the value the
// numpy half prints too, so the harness can check both did the same work.
double one_pass(const std::vector<colorlab::analysis::TermSet>& sets, const colorlab::analysis::ChartData& chart,
                const colorlab::analysis::FitOptions& o) {
  double check = 0;
  for (std::size_t i = 0; i < sets.size(); ++i) {
    FitReport r = colorlab::analysis::fit_report(sets[i], chart, o, colorlab::analysis::CvSpec::loo());
    benchmark::DoNotOptimize(r);
    if (i == 24) check = r.cv.s00.mean;
  }
  return check;
}

colorlab::analysis::FitOptions options() {
  colorlab::analysis::FitOptions o;
  o.input_scale = 1.0;
  return o;
}

void BM_AllSetsWithLoo(benchmark::State& state) {
  auto file = colorlab::paths::shared_data_file("testvec_sg140_canon20d_d50_argyll.csv");
  if (!file) {
    state.SkipWithError("testvec_sg140_canon20d_d50_argyll.csv not present (../shared/data)");
    return;
  }
  const auto chart = colorlab::analysis::read_chart(*file);
  const auto sets = colorlab::analysis::all_term_sets();
  const auto o = options();
  for (auto _ : state) benchmark::DoNotOptimize(one_pass(sets, chart, o));
}
BENCHMARK(BM_AllSetsWithLoo)->Unit(benchmark::kMillisecond);

int serve(const char* csv) {
  std::string path;
  if (csv) {
    path = csv;
  } else if (auto file = colorlab::paths::shared_data_file("testvec_sg140_canon20d_d50_argyll.csv")) {
    path = file->string();
  } else {
    std::cerr << "testvec_sg140_canon20d_d50_argyll.csv not present (../shared/data)\n";
    return 1;
  }
  const auto chart = colorlab::analysis::read_chart(path);
  const auto sets = colorlab::analysis::all_term_sets();
  const auto o = options();
  one_pass(sets, chart, o);  // warm-up, as the numpy half does
  std::string line;
  while (std::getline(std::cin, line)) {
    const int n = std::stoi(line);
    std::string out;
    double check = 0;
    for (int i = 0; i < n; ++i) {
      auto t0 = std::chrono::steady_clock::now();
      check = one_pass(sets, chart, o);
      auto t1 = std::chrono::steady_clock::now();
      out += " " + std::to_string(std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count());
    }
    std::printf("%.6f%s\n", check, out.c_str());
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 2 && std::strcmp(argv[1], "--serve") == 0) return serve(argc >= 3 ? argv[2] : nullptr);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
