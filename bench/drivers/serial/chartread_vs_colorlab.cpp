// ArgyllCMS chartread against colorlab's Spectrolino driver, both driven for real on the simulated
// SpectroScan T at time scale 1 (real device and wire time), on the same strip: row 3 of the Scene's
// ColorChecker SG, columns A onwards. chartread runs through the conformance tests' harness
// (tests/sim/conformance/argyll_driver.py: root, unshare, private /dev, a pty for its prompts) under
// strace, and bench/drivers/serial/serial_timeline.py cuts its serial traffic into phases. Each
// client gets a fresh colorlab-sim with the same seed. The main prints both, the ratio, and an
// extrapolation to the 140-patch chart with the calibration schedule each client uses.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <boost/asio/io_context.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/drivers/serpentine.hpp"
#include "colorlab/drivers/spectrolino.hpp"
#include "colorlab/sim/scene.hpp"
#include "run_support.hpp"   // tests/drivers/serial: runs a driver coroutine with a hard limit
#include "sim_process.hpp"    // tests/sim/serial: colorlab-sim as a child process
#include "colorlab/testing/process.hpp"

namespace {

using namespace colorlab;
using Clock = std::chrono::steady_clock;
using json = nlohmann::json;

constexpr int kRow = 3;
constexpr int kChartPatches = 140;
constexpr int kCalInterval = 50;        // both clients: white recalibration every 50 reflective readings
constexpr int kArgyllStepsInPass = 39;  // printtarg -i SS -p A4 puts 140 patches in strips of 39

const std::string kLabToml = R"(
time_scale = 1.0
[ls110]
enabled = false
[dmx]
enabled = false
[genicam]
enabled = false
)";

// One client's run, in seconds.
struct Run {
  bool done = false;
  std::string why;  // set when the run could not happen
  double init = 0, locate = 0, calibrate = 0, first_patch = 0, steady_patch = 0, patches = 0;
  int calibrations = 0, commands = 0;
  unsigned baud = 0;           // link speed the client left the device at
  double measure_answer = 0;   // chartread only: mean D0 07 round trip (patches 2..N)
  double extra_queries = 0;    // chartread only: mean time in the other commands of a patch (BA 09 04)
  double read_wait = 0;        // chartread only: mean time per patch blocked in read() (VMIN/VTIME)
  json phase_split;            // chartread only: init and calibration cut into device wait, VTIME, host gaps
  std::vector<double> cycles;  // per patch, from its measure command to the next one
  double total() const { return init + locate + calibrate + patches; }
};
Run g_argyll, g_colorlab;
int g_patches = 0;

using colorlab::testing::on_path;
using colorlab::testing::shell_output;

std::string sg_patch(int column) { return std::string(1, static_cast<char>('A' + column)) + std::to_string(kRow); }

// Table coordinates of the strip's patches, from the simulator's own placement of the head.
std::vector<std::pair<double, double>> strip_mm(const test::SimProcess& sim, int patches) {
  std::vector<std::pair<double, double>> xy;
  for (int c = 0; c < patches; ++c) {
    auto r = sim.control({{"cmd", "place"}, {"target", "patch"}, {"patch", sg_patch(c)}});
    if (!r.value("ok", false)) throw std::runtime_error("simulator cannot place the head on " + sg_patch(c));
    xy.emplace_back(r["spectrolino"]["head_mm"][0].get<double>(), r["spectrolino"]["head_mm"][1].get<double>());
  }
  sim.control({{"cmd", "place"}, {"x_mm", 0.0}, {"y_mm", 0.0}});  // both clients start from home
  return xy;
}

void finish_patch_stats(Run& r) {
  r.first_patch = r.cycles.front();
  double sum = 0;
  for (std::size_t i = 1; i < r.cycles.size(); ++i) sum += r.cycles[i];
  r.steady_patch = r.cycles.size() > 1 ? sum / static_cast<double>(r.cycles.size() - 1) : r.first_patch;
}

std::filesystem::path keep_dir() {
  auto d = std::filesystem::temp_directory_path() / "colorlab-chartread-vs-colorlab";
  std::filesystem::create_directories(d);
  return d;
}

std::string why_argyll_cannot_run() {
  if (::geteuid() != 0) return "chartread needs root for unshare -m and a private /dev (instrument-protocols §5.3)";
  for (const char* t : {"chartread", "targen", "printtarg", "unshare", "strace", "python3"}) {
    if (!on_path(t)) return std::string(t) + " is not installed";
  }
  return {};
}

void BM_ArgyllChartread(benchmark::State& state) {
  const int patches = static_cast<int>(state.range(0));
  g_patches = patches;
  if (auto why = why_argyll_cannot_run(); !why.empty()) {
    g_argyll.why = why;
    state.SkipWithError(why.c_str());
    return;
  }
  for (auto _ : state) {
    test::SimProcess sim(kLabToml);
    auto xy = strip_mm(sim, patches);
    auto coord = [](std::pair<double, double> p) { return std::to_string(p.first) + "," + std::to_string(p.second); };
    const std::string src = COLORLAB_SOURCE_DIR;
    const auto trace = sim.dir() / "chartread.strace";
    const auto log = sim.dir() / "chartread.log";
    std::string cmd = "timeout 900 python3 " + src + "/tests/sim/conformance/argyll_driver.py chartread --port " +
                      sim.port("spectrolino") + " --control " + sim.announcement()["control"].get<std::string>() +
                      " --workdir " + sim.dir().string() + " --patches " + std::to_string(patches) + " --first " +
                      coord(xy.front()) + " --last " + coord(xy.back()) + " --read-timeout 600 --log " +
                      log.string() + " --trace " + trace.string();
    auto result = json::parse(shell_output(cmd), nullptr, false);
    for (const auto& f : {trace, log}) {
      std::error_code ec;
      std::filesystem::copy_file(f, keep_dir() / f.filename(), std::filesystem::copy_options::overwrite_existing, ec);
    }
    if (result.is_discarded() || !result.value("ok", false)) {
      g_argyll.why = "chartread run failed: " + (result.is_discarded() ? std::string("no JSON") : result.dump()) +
                     " (log kept in " + keep_dir().string() + ")";
      state.SkipWithError(g_argyll.why.c_str());
      return;
    }
    if (result["patches"].size() != static_cast<std::size_t>(patches)) {
      g_argyll.why = "chartread returned " + std::to_string(result["patches"].size()) + " patches";
      state.SkipWithError(g_argyll.why.c_str());
      return;
    }
    auto t = json::parse(shell_output("python3 " + src + "/bench/drivers/serial/serial_timeline.py " + trace.string() +
                               " --patches " + std::to_string(patches)),
                         nullptr, false);
    if (t.is_discarded()) {
      g_argyll.why = "could not read chartread's serial trace";
      state.SkipWithError(g_argyll.why.c_str());
      return;
    }
    Run& r = g_argyll;
    r.init = t["init_s"];
    r.locate = t["locate_s"];
    r.calibrate = t["calibrate_s"];
    r.patches = t["patches_s"];
    r.calibrations = t["calibrations"];
    r.commands = t["commands_to_last_patch"];
    r.baud = sim.control({{"cmd", "truth"}})["spectrolino"]["baud"].get<unsigned>();
    r.phase_split = {{"init", t["init_split"]}, {"calibration", t["calibrate_split"]}};
    const auto& pp = t["per_patch"];
    for (std::size_t i = 1; i < pp.size(); ++i) {
      r.measure_answer += pp[i]["measure_answer"].get<double>() / static_cast<double>(pp.size() - 1);
      r.read_wait += pp[i]["read_wait"].get<double>() / static_cast<double>(pp.size() - 1);
      r.extra_queries += (pp[i]["in_commands"].get<double>() - pp[i]["measure_answer"].get<double>()) /
                         static_cast<double>(pp.size() - 1);
    }
    // Cycle = from one D0 07 to the next; the last patch ends with its last answer.
    for (const auto& p : t["per_patch"]) r.cycles.push_back(p["cycle"].get<double>());
    finish_patch_stats(r);
    r.done = true;
    state.SetIterationTime(r.total());
  }
  state.counters["init_s"] = g_argyll.init;
  state.counters["locate_s"] = g_argyll.locate;
  state.counters["calibrate_s"] = g_argyll.calibrate;
  state.counters["patch_s"] = g_argyll.steady_patch;
  state.counters["commands"] = g_argyll.commands;
}

void BM_ColorlabReadChart(benchmark::State& state) {
  const int patches = static_cast<int>(state.range(0));
  g_patches = patches;
  for (auto _ : state) {
    test::SimProcess sim(kLabToml);
    auto xy = strip_mm(sim, patches);
    boost::asio::io_context io;
    drivers::SpectrolinoOptions o;
    o.port = sim.port("spectrolino");
    o.simulated = true;
    drivers::Spectrolino driver(io.get_executor(), o);
    drivers::ChartLayout layout;
    layout.origin_x_mm = xy[0].first;
    layout.origin_y_mm = xy[0].second;
    layout.step_x_mm = xy[1].first - xy[0].first;
    layout.step_y_mm = xy[1].second - xy[0].second;
    layout.patches_per_strip = patches;
    layout.strips = 1;

    Run& r = g_colorlab;
    auto t0 = Clock::now();
    test::run(io, driver.connect(), std::chrono::seconds(120));
    auto t1 = Clock::now();
    test::run(io, driver.calibrate(), std::chrono::seconds(120));  // read_chart then starts calibrated, as Argyll does
    auto t2 = Clock::now();
    std::vector<Clock::time_point> done;
    auto readings = test::run(io, driver.read_chart(layout, [&](int, int) { done.push_back(Clock::now()); }),
                              std::chrono::seconds(1800));
    benchmark::DoNotOptimize(readings);
    auto secs = [](Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); };
    r.init = secs(t0, t1);
    r.calibrate = secs(t1, t2);
    r.patches = secs(t2, done.back());
    auto prev = t2;
    for (auto d : done) {
      r.cycles.push_back(secs(prev, d));
      prev = d;
    }
    finish_patch_stats(r);
    r.calibrations = driver.calibrations_done();
    r.commands = static_cast<int>(driver.commands_sent());
    r.baud = sim.control({{"cmd", "truth"}})["spectrolino"]["baud"].get<unsigned>();
    r.done = true;
    driver.disconnect();
    state.SetIterationTime(r.total());
  }
  state.counters["init_s"] = g_colorlab.init;
  state.counters["calibrate_s"] = g_colorlab.calibrate;
  state.counters["patch_s"] = g_colorlab.steady_patch;
  state.counters["commands"] = g_colorlab.commands;
}

BENCHMARK(BM_ArgyllChartread)->Arg(14)->Iterations(1)->UseManualTime()->Unit(benchmark::kSecond);
BENCHMARK(BM_ColorlabReadChart)->Arg(14)->Iterations(1)->UseManualTime()->Unit(benchmark::kSecond);

// White calibrations for a chart read in rows of these lengths: one before the first row, and one at
// the start of any row that would carry the count past the interval (Argyll ss.c read_xy; colorlab's
// read_chart does the same).
int calibrations_for(const std::vector<int>& rows) {
  int cals = 0, since = kCalInterval;
  for (int n : rows) {
    if (since + n > kCalInterval) {
      ++cals;
      since = 0;
    }
    since += n;
  }
  return cals;
}

std::vector<int> chunks(int total, int per_row) {
  std::vector<int> rows;
  for (int left = total; left > 0; left -= per_row) rows.push_back(std::min(left, per_row));
  return rows;
}

// The SG's 14 × 10 patches in the order colorlab's serpentine visits them.
std::vector<int> colorlab_sg_rows() {
  drivers::ChartLayout l;
  l.origin_x_mm = 31.2;
  l.origin_y_mm = 29.5;
  l.step_y_mm = 19;
  l.pass_x_mm = 19;
  l.patches_per_strip = sim::chart_rows;
  l.strips = sim::chart_columns;
  std::vector<int> rows;
  for (const auto& row : drivers::serpentine_rows(l)) rows.push_back(static_cast<int>(row.size()));
  return rows;
}

// Every calibration is followed by one "first patch" (travel from the white tile); the rest run at
// the steady per-patch time of this strip's 19 mm pitch.
double extrapolate(const Run& r, int cals) {
  return r.init + r.locate + cals * (r.calibrate + r.first_patch) + (kChartPatches - cals) * r.steady_patch;
}

void print_report() {
  const Run& a = g_argyll;
  const Run& c = g_colorlab;
  std::printf("\n== ArgyllCMS chartread vs colorlab Spectrolino driver: %d patches, SG row %d, time scale 1 ==\n",
              g_patches, kRow);
  if (!a.done) std::printf("chartread did not run: %s\n", a.why.c_str());
  if (!c.done) std::printf("colorlab did not run\n");
  if (!a.done || !c.done) return;
  auto row = [](const char* what, double av, double cv) {
    std::printf("%-34s %10.3f %10.3f %8.2fx\n", what, av, cv, cv > 0 ? av / cv : 0.0);
  };
  std::printf("%-34s %10s %10s %9s\n", "phase (s)", "chartread", "colorlab", "ratio");
  row("init (open .. ready)", a.init, c.init);
  row("locate (operator prompts, Argyll)", a.locate, c.locate);
  row("white calibration", a.calibrate, c.calibrate);
  row("first patch (from the tile)", a.first_patch, c.first_patch);
  row("per patch, steady (mean 2..N)", a.steady_patch, c.steady_patch);
  row("all patches", a.patches, c.patches);
  row("total, init .. last patch", a.total(), c.total());
  row("total without init/locate", a.calibrate + a.patches, c.calibrate + c.patches);
  std::printf("%-34s %10d %10d\n", "serial commands", a.commands, c.commands);
  std::printf("%-34s %10d %10d\n", "white calibrations", a.calibrations, c.calibrations);
  std::printf("\nper patch cycle (s):\n  #   chartread  colorlab  ratio\n");
  for (std::size_t i = 0; i < a.cycles.size() && i < c.cycles.size(); ++i) {
    std::printf("%3zu %10.3f %9.3f %6.2fx\n", i + 1, a.cycles[i], c.cycles[i], a.cycles[i] / c.cycles[i]);
  }
  // Where a steady patch's time goes. The D0 07 request and its spectrum answer are 15 + 303 bytes
  // (10 bits each at 8N1); the device time is the same simulator model for both clients.
  const double d007_bits = (15 + 303) * 10.0;
  const double device = a.measure_answer - d007_bits / a.baud;
  const double wire_a = d007_bits / a.baud, wire_c = d007_bits / c.baud;
  std::printf("\nsteady patch decomposition (s)     chartread   colorlab\n");
  std::printf("%-34s %10u %10u\n", "link speed (baud)", a.baud, c.baud);
  std::printf("%-34s %10.3f %10.3f\n", "device time (D0 07, simulator)", device, device);
  std::printf("%-34s %10.3f %10.3f\n", "D0 07 wire time", wire_a, wire_c);
  std::printf("%-34s %10.3f %10.3f\n", "BA 09 04 XYZ query (device+wire)", a.extra_queries - a.read_wait, 0.0);
  std::printf("%-34s %10.3f %10.3f\n", "read() VMIN/VTIME waits", a.read_wait, 0.0);
  std::printf("%-34s %10.3f %10.3f\n", "host: gaps between commands", a.steady_patch - device - wire_a - a.extra_queries,
              c.steady_patch - device - wire_c);
  std::printf("%-34s %10.3f %10.3f\n", "= per patch", a.steady_patch, c.steady_patch);
  std::printf("ceiling with zero host and wire time: %.2fx per patch\n", a.steady_patch / device);
  std::printf("\nchartread phases (s)   waiting for answers (of which read() VTIME)   host gaps\n");
  for (const char* phase : {"init", "calibration"}) {
    const auto& p = a.phase_split[phase];
    std::printf("%-22s %20.3f %12.3f %20.3f\n", phase, p["waiting_for_device"].get<double>(),
                p["read_wait"].get<double>(), p["host_gaps"].get<double>());
  }
  const int cals_a = calibrations_for(chunks(kChartPatches, kArgyllStepsInPass));
  const int cals_c = calibrations_for(colorlab_sg_rows());
  const double ta = extrapolate(a, cals_a), tc = extrapolate(c, cals_c);
  const double ia = a.init + a.locate, ic = c.init + c.locate;
  std::printf("\n140 patches extrapolated (chartread: %d calibrations, strips of %d; colorlab: %d calibrations, "
              "rows of %d)\n",
              cals_a, kArgyllStepsInPass, cals_c, sim::chart_columns);
  std::printf("%-34s %10.1f %10.1f %8.2fx\n", "init .. last patch (s)", ta, tc, ta / tc);
  std::printf("%-34s %10.1f %10.1f %8.2fx\n", "chart read only, no init/locate (s)", ta - ia, tc - ic,
              (ta - ia) / (tc - ic));
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  print_report();
  return 0;
}
