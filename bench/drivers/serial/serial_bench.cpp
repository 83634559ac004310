// Spectrolino/SpectroScan T driver speed against the simulator at time scale 1 (real device and
// wire time): a chart read, and the per-command overhead above wire time + device time.
// ArgyllCMS chartread itself is driven on the same simulator by bench_chartread_vs_colorlab
// (chartread_vs_colorlab.cpp); see docs/PERFORMANCE.md ("Serial drivers").
#include <benchmark/benchmark.h>

#include <boost/asio/io_context.hpp>

#include "colorlab/drivers/spectrolino.hpp"
#include "colorlab/sim/clock.hpp"
#include "colorlab/sim/scene.hpp"
#include "colorlab/sim/spectrolino_sim.hpp"
#include "run_support.hpp"  // tests/drivers/serial: runs a driver coroutine with a hard limit

namespace {

using namespace colorlab;

struct Rig {
  boost::asio::io_context io;
  std::shared_ptr<sim::SimClock> clock = std::make_shared<sim::SimClock>(1.0);
  std::unique_ptr<sim::Scene> scene;
  std::shared_ptr<sim::SpectrolinoSim> sim;
  std::unique_ptr<drivers::Spectrolino> driver;

  explicit Rig(unsigned max_baud) {
    sim::SceneConfig sc;
    sc.force_synthetic_chart = true;
    scene = std::make_unique<sim::Scene>(sc, clock);
    sim = std::make_shared<sim::SpectrolinoSim>(io.get_executor(), *scene, sim::SpectrolinoConfig{}, 11, 1.0);
    sim->start();
    drivers::SpectrolinoOptions o;
    o.port = sim->port_path();
    o.simulated = true;
    o.max_baud = max_baud;
    driver = std::make_unique<drivers::Spectrolino>(io.get_executor(), o);
    test::run(io, driver->connect(), std::chrono::seconds(120));
  }
  ~Rig() {
    driver->disconnect();
    sim->stop();
    test::settle(io, std::chrono::milliseconds(5));
  }

  drivers::ChartLayout layout(int patches) const {
    const auto& cfg = sim->model().config();
    const auto& p = scene->chart().patches;
    drivers::ChartLayout l;
    l.origin_x_mm = cfg.chart_origin_x_mm + p[0].x_mm + p[0].size_mm / 2;
    l.origin_y_mm = cfg.chart_origin_y_mm + p[0].y_mm + p[0].size_mm / 2;
    l.step_y_mm = p[1].y_mm - p[0].y_mm;
    l.pass_x_mm = p[10].x_mm - p[0].x_mm;
    l.patches_per_strip = sim::chart_rows;
    l.strips = sim::chart_columns;
    l.patch_count = patches;
    return l;
  }
};

double wire_seconds(std::size_t bytes, unsigned baud) { return static_cast<double>(bytes) * 10.0 / baud; }

// Chart read at time scale 1. Counters: seconds per chart, per patch, commands sent.
void BM_ChartRead(benchmark::State& state) {
  const int patches = static_cast<int>(state.range(0));
  const unsigned baud = static_cast<unsigned>(state.range(1));
  Rig rig(baud);
  std::uint64_t commands = 0;
  int cals = 0;
  for (auto _ : state) {
    auto t0 = std::chrono::steady_clock::now();
    auto c0 = rig.driver->commands_sent();
    auto k0 = rig.driver->calibrations_done();
    auto readings = test::run(rig.io, rig.driver->read_chart(rig.layout(patches)), std::chrono::seconds(3600));
    benchmark::DoNotOptimize(readings);
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    commands = rig.driver->commands_sent() - c0;
    cals = rig.driver->calibrations_done() - k0;
  }
  state.counters["patches"] = patches;
  state.counters["baud"] = baud;
  state.counters["commands"] = static_cast<double>(commands);
  state.counters["calibrations"] = cals;
}
BENCHMARK(BM_ChartRead)
    ->Args({14, 57600})
    ->Args({14, 9600})
    ->Args({140, 57600})
    ->Args({140, 9600})
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kSecond);

// One short table command (D0 24 status → D1 83 xx) at time scale 1. overhead_ms = measured −
// (device time + wire time of request and answer at the link's speed).
void BM_CommandOverhead(benchmark::State& state) {
  const unsigned baud = static_cast<unsigned>(state.range(0));
  Rig rig(baud);
  const double device_s = rig.sim->model().timing().command_s;
  const double wire_s = wire_seconds(std::string(";D024\r\n").size() + std::string(":D18310\r\n").size(), baud);
  double total = 0;
  std::int64_t n = 0;
  for (auto _ : state) {
    auto t0 = std::chrono::steady_clock::now();
    auto st = test::run(rig.io, rig.driver->table_status());
    benchmark::DoNotOptimize(st);
    double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    state.SetIterationTime(s);
    total += s;
    ++n;
  }
  double mean = total / static_cast<double>(n);
  state.counters["device_ms"] = device_s * 1e3;
  state.counters["wire_ms"] = wire_s * 1e3;
  state.counters["overhead_ms"] = (mean - device_s - wire_s) * 1e3;
  // spotread on the same simulator: ~124 ms per command (§5.4), device + wire included.
  state.counters["spotread_ratio"] = 0.124 / mean;
}
BENCHMARK(BM_CommandOverhead)->Arg(57600)->Arg(9600)->Iterations(50)->UseManualTime()->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
