// ArgyllCMS chartread against colorlab's Spectrolino driver on the simulated SpectroScan T, reading the
// same patches of the Scene's ColorChecker SG: whole rows of 14, up to the full 140-patch chart.
//
// Timed the same way on both sides, in one run, alternating (Argyll, colorlab, colorlab, Argyll, ...),
// each client on a fresh colorlab-sim with the same seed and time scale, no tracer on either:
// - chartread runs through the conformance tests' harness (tests/sim/conformance/argyll_driver.py: root,
//   unshare, private /dev, a pty for its prompts) on a targen/printtarg chart whose page (160 × 122 mm)
//   makes passes of 14 patches, one pass per SG row; the "operator" puts the sight on the three patches
//   chartread asks for (first and last of the first pass, first of the last pass), which fixes the same
//   19 mm grid. The harness's wall clock stamps its prompts and "Sheet 1 of 1 read OK".
// - colorlab: connect(), calibrate(), read_chart() over the same rows, stamped with steady_clock. Its
//   device time is measured in the same run from the driver's own transcript: each D0 07 round trip
//   (request written .. answer's last byte read) minus the wire time of its bytes at the link's speed.
// Both sides' readings are checked to be of the same SG patches (each of chartread's spectra is nearest
// to colorlab's reading of the patch it maps to). With --trace, an extra chartread run under strace (not
// part of the comparison) cuts Argyll's serial traffic into per-patch parts (serial_timeline.py).
#include <unistd.h>

#include <boost/asio/io_context.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/drivers/spectrolino.hpp"
#include "colorlab/testing/process.hpp"
#include "run_support.hpp"  // tests/drivers/serial: runs a driver coroutine with a hard limit
#include "sim_process.hpp"  // tests/sim/serial: colorlab-sim as a child process

namespace {

using namespace colorlab;
using Clock = std::chrono::steady_clock;
using json = nlohmann::json;
using colorlab::testing::on_path;
using colorlab::testing::shell_output;

constexpr int kColumns = 14;          // SG columns A..N: one row is one Argyll pass
constexpr int kRows = 10;             // SG rows 1..10
const char* kArgyllPage = "160x122";  // printtarg -i SS: 14 steps per pass, 10 passes on one page

struct Options {
  int patches = 140;
  double time_scale = 1.0;
  int pairs = 1;
  bool trace = false;
  std::string json_out;
};

std::string lab_toml(double time_scale) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", time_scale);
  return std::string("time_scale = ") + buf +
         "\n[ls110]\nenabled = false\n[dmx]\nenabled = false\n[genicam]\nenabled = false\n[dslr]\nenabled = false\n";
}

std::string loadavg() {
  std::ifstream f("/proc/loadavg");
  std::string a, b, c;
  f >> a >> b >> c;
  return a + " " + b + " " + c;
}

double secs(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

std::string sg_name(int column, int row) { return std::string(1, static_cast<char>('A' + column)) + std::to_string(row + 1); }

std::pair<double, double> place(const test::SimProcess& sim, const std::string& patch) {
  auto r = sim.control({{"cmd", "place"}, {"target", "patch"}, {"patch", patch}});
  if (!r.value("ok", false)) throw std::runtime_error("simulator cannot place the head on " + patch);
  return {r["spectrolino"]["head_mm"][0].get<double>(), r["spectrolino"]["head_mm"][1].get<double>()};
}

// One client's run. Times in wall seconds at the run's time scale.
struct Run {
  std::string client;
  bool done = false;
  std::string why;
  std::string load_before, load_after;
  double init = 0;    // start .. ready for the chart (chartread: its "place sheet" prompt)
  double locate = 0;  // chartread only: sheet prompt .. the last sight answered
  double read = 0;    // colorlab: calibrate() + read_chart(); chartread: located .. "read OK" (its calibrations inside)
  double total() const { return init + locate + read; }
  unsigned baud = 0;
  std::uint64_t sim_lines = 0, sim_measurements = 0;  // what the simulator answered (its own counters)
  // colorlab only, measured in this run:
  int calibrations = 0;
  double device_per_patch = 0;                 // mean D0 07 round trip minus its wire time
  double wire_per_patch = 0;                   // mean D0 07 request + answer bytes at the link speed
  double host_per_patch = 0;                   // median of a patch's cycle minus its D0 07 round trip (ms resolution)
  double cycle_per_patch = 0;                  // read_chart's time / patches (its recalibrations included)
  std::map<int, std::vector<double>> spectra;  // chart index (row * 14 + column) → reflectance
};

json to_json(const Run& r) {
  json j{
      {"client", r.client},
      {"done", r.done},
      {"why", r.why},
      {"load_before", r.load_before},
      {"load_after", r.load_after},
      {"init_s", r.init},
      {"locate_s", r.locate},
      {"read_s", r.read},
      {"total_s", r.total()},
      {"baud", r.baud},
      {"sim_lines_answered", r.sim_lines},
      {"sim_measurements", r.sim_measurements},
  };
  if (r.client == "colorlab") {
    j["calibrations"] = r.calibrations;
    j["device_per_patch_s"] = r.device_per_patch;
    j["wire_per_patch_s"] = r.wire_per_patch;
    j["host_per_patch_s"] = r.host_per_patch;
    j["cycle_per_patch_s"] = r.cycle_per_patch;
  }
  return j;
}

void read_sim_counters(const test::SimProcess& sim, Run& r) {
  auto t = sim.control({{"cmd", "truth"}})["spectrolino"];
  r.baud = t["baud"].get<unsigned>();
  r.sim_lines = t["lines_answered"].get<std::uint64_t>();
  r.sim_measurements = t["measurements"].get<std::uint64_t>();
}

std::string why_argyll_cannot_run(bool trace) {
  if (::geteuid() != 0) return "chartread needs root for unshare -m and a private /dev (instrument-protocols §5.3)";
  for (const char* t : {"chartread", "targen", "printtarg", "unshare", "python3"}) {
    if (!on_path(t)) return std::string(t) + " is not installed";
  }
  if (trace && !on_path("strace")) return "strace is not installed (needed for --trace only)";
  return {};
}

std::filesystem::path keep_dir() {
  auto d = std::filesystem::temp_directory_path() / "colorlab-chartread-vs-colorlab";
  std::filesystem::create_directories(d);
  return d;
}

// chartread on `rows` SG rows; with `trace` under strace (then its figures are not the comparison's).
Run run_argyll(const Options& o, bool trace, json* timeline = nullptr) {
  Run r;
  r.client = "chartread";
  if (auto why = why_argyll_cannot_run(trace); !why.empty()) {
    r.why = why;
    return r;
  }
  const int rows = o.patches / kColumns;
  test::SimProcess sim(lab_toml(o.time_scale));
  // The patches chartread asks the operator to sight: its pass A (SG row 1) steps 1 and 14, and the
  // first step of its last pass (the SG's last row read), when there is more than one pass.
  auto coord = [](std::pair<double, double> p) { return std::to_string(p.first) + "," + std::to_string(p.second); };
  std::string locate = " --locate A1=" + coord(place(sim, sg_name(0, 0))) + " --locate A" + std::to_string(kColumns) +
                       "=" + coord(place(sim, sg_name(kColumns - 1, 0)));
  if (rows > 1) locate += " --locate " + std::string(1, static_cast<char>('A' + rows - 1)) + "1=" + coord(place(sim, sg_name(0, rows - 1)));
  sim.control({{"cmd", "place"}, {"x_mm", 0.0}, {"y_mm", 0.0}});  // both clients start from home
  const std::string src = COLORLAB_SOURCE_DIR;
  const auto log = sim.dir() / (trace ? "chartread-traced.log" : "chartread.log");
  const auto trace_file = sim.dir() / "chartread.strace";
  std::string cmd = "timeout 1800 /usr/bin/python3 " + src + "/tests/sim/conformance/argyll_driver.py chartread --port " +
                    sim.port("spectrolino") + " --control " + sim.announcement()["control"].get<std::string>() +
                    " --workdir " + sim.dir().string() + " --patches " + std::to_string(o.patches) + " --page " +
                    kArgyllPage + locate + " --read-timeout 1500 --log " + log.string() +
                    (trace ? " --trace " + trace_file.string() : std::string());
  r.load_before = loadavg();
  auto result = json::parse(shell_output(cmd), nullptr, false);
  r.load_after = loadavg();
  for (const auto& f : {log, trace_file, sim.dir() / "chart.ti2", sim.dir() / "chart.ti3"}) {
    std::error_code ec;
    if (std::filesystem::exists(f)) std::filesystem::copy_file(f, keep_dir() / f.filename(), std::filesystem::copy_options::overwrite_existing, ec);
  }
  if (result.is_discarded() || !result.value("ok", false)) {
    r.why = "chartread run failed: " + (result.is_discarded() ? std::string("no JSON") : result.dump()) +
            " (log kept in " + keep_dir().string() + ")";
    return r;
  }
  if (result["patches"].size() != static_cast<std::size_t>(o.patches)) {
    r.why = "chartread returned " + std::to_string(result["patches"].size()) + " patches";
    return r;
  }
  const auto& t = result["times"];
  r.init = t["sheet_prompt"].get<double>() - t["start"].get<double>();
  r.locate = t["located"].get<double>() - t["sheet_prompt"].get<double>();
  r.read = t["read_ok"].get<double>() - t["located"].get<double>();
  read_sim_counters(sim, r);
  // chartread's location "<pass><step>": pass = SG row, step = SG column.
  for (const auto& [loc, spectrum] : result["patches"].items()) {
    const int row = loc[0] - 'A';
    const int column = std::stoi(loc.substr(1)) - 1;
    r.spectra[row * kColumns + column] = spectrum.get<std::vector<double>>();
  }
  if (trace && timeline) {
    *timeline = json::parse(shell_output("/usr/bin/python3 " + src + "/bench/drivers/serial/serial_timeline.py " +
                                         trace_file.string() + " --patches " + std::to_string(o.patches)),
                            nullptr, false);
  }
  r.done = true;
  return r;
}

// Bytes a transcript line carries (its escapes undone).
std::size_t raw_bytes(const std::string& escaped) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < escaped.size(); ++i, ++n) {
    if (escaped[i] != '\\') continue;
    if (i + 1 < escaped.size() && escaped[i + 1] == 'x') i += 3;
    else ++i;
  }
  return n;
}

struct TranscriptLine {
  long ms = 0;
  char dir = ' ';  // '>' sent, '<' received
  std::string bytes;
};

std::vector<TranscriptLine> parse_transcript(const std::vector<std::string>& lines) {
  std::vector<TranscriptLine> out;
  for (const auto& l : lines) {  // "+<ms>ms -> <escaped>"
    auto ms_end = l.find("ms ");
    if (l.empty() || l[0] != '+' || ms_end == std::string::npos || l.size() < ms_end + 6) continue;
    TranscriptLine t;
    t.ms = std::stol(l.substr(1, ms_end - 1));
    const std::string dir = l.substr(ms_end + 3, 2);
    t.dir = dir == "->" ? '>' : dir == "<-" ? '<'
                                            : ' ';
    t.bytes = l.substr(ms_end + 6);
    out.push_back(std::move(t));
  }
  return out;
}

Run run_colorlab(const Options& o) {
  Run r;
  r.client = "colorlab";
  const int rows = o.patches / kColumns;
  test::SimProcess sim(lab_toml(o.time_scale));
  auto a1 = place(sim, sg_name(0, 0)), b1 = place(sim, sg_name(1, 0)), a2 = place(sim, sg_name(0, 1));
  sim.control({{"cmd", "place"}, {"x_mm", 0.0}, {"y_mm", 0.0}});  // both clients start from home
  boost::asio::io_context io;
  drivers::SpectrolinoOptions so;
  so.port = sim.port("spectrolino");
  so.simulated = true;
  drivers::Spectrolino driver(io.get_executor(), so);
  drivers::ChartLayout layout;  // rows of 14 along X, as colorlab's chart-read plans the SG
  layout.origin_x_mm = a1.first;
  layout.origin_y_mm = a1.second;
  layout.step_x_mm = b1.first - a1.first;
  layout.step_y_mm = b1.second - a1.second;
  layout.pass_x_mm = a2.first - a1.first;
  layout.pass_y_mm = a2.second - a1.second;
  layout.patches_per_strip = kColumns;
  layout.strips = rows;

  r.load_before = loadavg();
  auto t0 = Clock::now();
  test::run(io, driver.connect(), std::chrono::seconds(300));
  auto t1 = Clock::now();
  test::run(io, driver.calibrate(), std::chrono::seconds(300));  // read_chart then starts calibrated, as chartread does
  driver.transcript().clear();
  const auto t2 = Clock::now();
  std::vector<Clock::time_point> done;
  std::vector<double> rtt, wire;
  const double bits_per_byte = 10.0;  // 8N1
  auto progress = [&](int, int) {
    done.push_back(Clock::now());
    // The patch's D0 07: from its request to the last answer chunk before anything else is sent.
    auto lines = parse_transcript(driver.transcript().lines());
    driver.transcript().clear();
    for (std::size_t i = 0; i < lines.size(); ++i) {
      if (lines[i].dir != '>' || lines[i].bytes.rfind(";D007", 0) != 0) continue;
      long end = -1;
      std::size_t bytes = raw_bytes(lines[i].bytes);
      for (std::size_t k = i + 1; k < lines.size() && lines[k].dir == '<'; ++k) {
        end = lines[k].ms;
        bytes += raw_bytes(lines[k].bytes);
      }
      if (end < 0) continue;
      rtt.push_back((end - lines[i].ms) / 1000.0);
      // The simulator paces wire time like device time: both divided by the time scale.
      wire.push_back(static_cast<double>(bytes) * bits_per_byte / driver.baud() / o.time_scale);
    }
  };
  auto readings = test::run(io, driver.read_chart(layout, progress), std::chrono::seconds(3600));
  r.load_after = loadavg();
  r.init = secs(t0, t1);
  r.read = secs(t1, done.back());
  r.calibrations = driver.calibrations_done();
  const double n = static_cast<double>(rtt.size());
  for (std::size_t i = 0; i < rtt.size(); ++i) {
    r.device_per_patch += (rtt[i] - wire[i]) / n;
    r.wire_per_patch += wire[i] / n;
  }
  // Per patch: its cycle (from the previous patch's completion, the first from the end of calibrate()) minus
  // its D0 07 round trip is the host's part; the median leaves out the patches that recalibrated first.
  std::vector<double> host;
  for (std::size_t i = 0; i < done.size() && i < rtt.size(); ++i) host.push_back(secs(i ? done[i - 1] : t2, done[i]) - rtt[i]);
  r.cycle_per_patch = done.empty() ? 0 : secs(t2, done.back()) / static_cast<double>(done.size());
  if (!host.empty()) {
    std::nth_element(host.begin(), host.begin() + static_cast<long>(host.size() / 2), host.end());
    r.host_per_patch = host[host.size() / 2];
  }
  for (std::size_t i = 0; i < readings.size(); ++i) r.spectra[static_cast<int>(i)] = readings[i].values;
  read_sim_counters(sim, r);
  driver.disconnect();
  test::settle(io, std::chrono::milliseconds(5));
  r.done = rtt.size() == static_cast<std::size_t>(o.patches);
  if (!r.done) r.why = "measured " + std::to_string(rtt.size()) + " D0 07 round trips for " + std::to_string(o.patches) + " patches";
  return r;
}

// Whether both clients read the same SG patches: per chartread reading, the largest band difference to
// colorlab's reading of the patch it maps to, and whether colorlab's reading nearest to it is that patch or one
// alike (the SG repeats its neutrals: two patches are alike when colorlab's readings of them differ by at most
// kAlike in every band).
constexpr double kAlike = 0.02;

double max_band_difference(const std::vector<double>& x, const std::vector<double>& y) {
  double worst = 0;
  for (std::size_t k = 0; k < std::min(x.size(), y.size()); ++k) worst = std::max(worst, std::abs(x[k] - y[k]));
  return worst;
}

json same_patches(const Run& a, const Run& c) {
  int nearest_is_same = 0, nearest_is_alike = 0;
  double worst = 0;
  for (const auto& [idx, sa] : a.spectra) {
    auto mapped = c.spectra.find(idx);
    if (mapped == c.spectra.end()) continue;
    worst = std::max(worst, max_band_difference(sa, mapped->second));
    auto dist = [&](const std::vector<double>& sc) {
      double d = 0;
      for (std::size_t k = 0; k < std::min(sa.size(), sc.size()); ++k) d += (sa[k] - sc[k]) * (sa[k] - sc[k]);
      return d;
    };
    int best = -1;
    double best_d = 1e300;
    for (const auto& [j, sc] : c.spectra) {
      if (double d = dist(sc); d < best_d) best_d = d, best = j;
    }
    nearest_is_same += best == idx;
    nearest_is_alike += best == idx || max_band_difference(c.spectra.at(best), mapped->second) <= kAlike;
  }
  return {{"patches", a.spectra.size()},
          {"nearest_is_same_patch", nearest_is_same},
          {"nearest_is_same_or_alike_patch", nearest_is_alike},
          {"max_band_difference", worst}};
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
      return argv[++i];
    };
    if (a == "--patches") o.patches = std::stoi(value());
    else if (a == "--time-scale") o.time_scale = std::stod(value());
    else if (a == "--pairs") o.pairs = std::stoi(value());
    else if (a == "--trace") o.trace = true;
    else if (a == "--json") o.json_out = value();
    else {
      std::printf("usage: %s [--patches N (whole SG rows: 14, 28, .. 140; default 140)] [--time-scale S (default 1)]\n"
                  "          [--pairs P (default 1)] [--json FILE] [--trace (one more chartread run under strace, not compared)]\n",
                  argv[0]);
      std::exit(a == "--help" ? 0 : 2);
    }
  }
  if (o.patches < kColumns || o.patches > kColumns * kRows || o.patches % kColumns != 0) {
    throw std::runtime_error("--patches must be whole SG rows of 14: 14 .. 140");
  }
  return o;
}

void print_pair(const Run& a, const Run& c) {
  auto row = [](const char* what, double av, double cv) {
    std::printf("  %-40s %10.3f %10.3f %8.2fx\n", what, av, cv, cv > 0 ? av / cv : 0.0);
  };
  std::printf("  %-40s %10s %10s %9s\n", "phase (s, wall)", "chartread", "colorlab", "ratio");
  row("init (start .. ready for the chart)", a.init, c.init);
  row("locate (chartread's sight prompts)", a.locate, c.locate);
  row("calibrations + all patches", a.read, c.read);
  row("total, start .. last patch", a.total(), c.total());
  std::printf("  %-40s %10s %10s\n", "load average before / after", "", "");
  std::printf("    chartread %s / %s;  colorlab %s / %s\n", a.load_before.c_str(), a.load_after.c_str(),
              c.load_before.c_str(), c.load_after.c_str());
  std::printf("  %-40s %10llu %10llu\n", "serial lines the simulator answered", static_cast<unsigned long long>(a.sim_lines),
              static_cast<unsigned long long>(c.sim_lines));
  std::printf("  %-40s %10llu %10llu\n", "measurements the simulator made", static_cast<unsigned long long>(a.sim_measurements),
              static_cast<unsigned long long>(c.sim_measurements));
  std::printf("  %-40s %10u %10u\n", "link speed (baud)", a.baud, c.baud);
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  try {
    o = parse(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  std::printf("chartread vs colorlab: %d SG patches (%d rows of %d), time scale %g, %d pair(s), load average %s\n",
              o.patches, o.patches / kColumns, kColumns, o.time_scale, o.pairs, loadavg().c_str());
  json out{{"patches", o.patches}, {"time_scale", o.time_scale}, {"pairs", json::array()}};
  int failures = 0;
  for (int p = 0; p < o.pairs; ++p) {
    // Alternate who goes first: A C, C A, A C, ...
    Run a, c;
    if (p % 2 == 0) {
      a = run_argyll(o, false);
      c = run_colorlab(o);
    } else {
      c = run_colorlab(o);
      a = run_argyll(o, false);
    }
    std::printf("\n== pair %d (%s first) ==\n", p + 1, p % 2 == 0 ? "chartread" : "colorlab");
    if (!a.done) std::printf("  chartread did not run: %s\n", a.why.c_str());
    if (!c.done) std::printf("  colorlab did not run: %s\n", c.why.c_str());
    json pj{{"chartread", to_json(a)}, {"colorlab", to_json(c)}};
    if (a.done && c.done) {
      print_pair(a, c);
      auto same = same_patches(a, c);
      pj["same_patches"] = same;
      pj["ratio_total"] = a.total() / c.total();
      pj["ratio_read"] = a.read / c.read;
      std::printf("  same patches: of %d chartread readings, %d are nearest to colorlab's reading of the SG patch they map"
                  " to, %d to it or a patch alike (SG neutrals repeat; alike = within %.2f in every band);"
                  " largest band difference between the two readings of one patch %.2g\n",
                  o.patches, same["nearest_is_same_patch"].get<int>(), same["nearest_is_same_or_alike_patch"].get<int>(),
                  kAlike, same["max_band_difference"].get<double>());
      std::printf("  colorlab, measured in this run: %d white calibrations; per patch: D0 07 device time %.4f s, wire %.4f s,"
                  " host %.4f s (median); read_chart / patches %.4f s (recalibrations included)\n",
                  c.calibrations, c.device_per_patch, c.wire_per_patch, c.host_per_patch, c.cycle_per_patch);
      const double steady = c.device_per_patch + c.wire_per_patch + c.host_per_patch;
      std::printf("  colorlab's part of a patch beyond the device's own time: wire %.1f %%, host %.1f %% of %.4f s\n",
                  100.0 * c.wire_per_patch / steady, 100.0 * c.host_per_patch / steady, steady);
    } else {
      ++failures;
    }
    out["pairs"].push_back(pj);
  }
  if (o.trace) {
    json timeline;
    Run t = run_argyll(o, true, &timeline);
    out["traced_chartread"] = {{"run", to_json(t)}, {"timeline", timeline}};
    std::printf("\n== chartread under strace (a separate run, not part of the comparison) ==\n");
    if (!t.done) {
      std::printf("  did not run: %s\n", t.why.c_str());
    } else {
      std::printf("  total %.3f s (init %.3f, locate %.3f, read %.3f); load %s / %s\n", t.total(), t.init, t.locate, t.read,
                  t.load_before.c_str(), t.load_after.c_str());
      if (timeline.is_object() && timeline.contains("per_patch") && timeline["per_patch"].size() > 1) {
        // Means over patches 2..N (the first travels from the white tile), in wall seconds at the run's scale.
        const auto& pp = timeline["per_patch"];
        std::printf("  per patch (mean of 2..%zu, s):", pp.size());
        for (const char* k : {"cycle", "measure_answer", "in_commands", "read_wait", "host_gaps"}) {
          double sum = 0;
          for (std::size_t i = 1; i < pp.size(); ++i) sum += pp[i].value(k, 0.0);
          std::printf(" %s %.4f", k, sum / static_cast<double>(pp.size() - 1));
        }
        std::printf("\n  init split %s; calibration split %s\n", timeline["init_split"].dump().c_str(),
                    timeline["calibrate_split"].dump().c_str());
      } else {
        std::printf("  could not read the trace's timeline\n");
      }
    }
  }
  if (!o.json_out.empty()) std::ofstream(o.json_out) << out.dump(2) << "\n";
  return failures ? 1 : 0;
}
