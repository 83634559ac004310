// Writes a bench's backlog for ship_speed.py: RUNS ended chart-read runs of MEASUREMENTS measurements each into
// a colorlabd state directory, through colorlabd's own Store (the same rows, events and log positions the daemon
// writes), PER_STEP measurements (each under its own patch name) a committed step so that a million rows do not
// cost a million fsyncs. No blobs: blob uploads are timed on their own (blob_speed.py).
//
// Usage: bench_fleet_backlog STATE_DIR RUNS MEASUREMENTS [PER_STEP=100]
#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <random>
#include <string>

#include "colorlab/store/store.hpp"

namespace {

int positive(const char* text, const char* what) {
  char* end = nullptr;
  const long v = std::strtol(text, &end, 10);
  if (*end != '\0' || v < 1 || v > 100000000) {
    std::cerr << what << " must be a positive integer, not '" << text << "'\n";
    std::exit(2);
  }
  return static_cast<int>(v);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4 || argc > 5) {
    std::cerr << "usage: bench_fleet_backlog STATE_DIR RUNS MEASUREMENTS [PER_STEP=100]\n";
    return 2;
  }
  using namespace colorlab;
  const int runs = positive(argv[2], "RUNS"), per_run = positive(argv[3], "MEASUREMENTS");
  const int per_step = argc == 5 ? positive(argv[4], "PER_STEP") : 100;
  std::filesystem::create_directories(argv[1]);
  store::Store store(std::filesystem::path(argv[1]) / "colorlab.db");
  std::mt19937_64 rng(22);
  std::uniform_real_distribution<double> value(0.0, 100.0);
  for (int r = 0; r < runs; ++r) {
    store::NewRun nr;
    nr.campaign = "chart-read";
    nr.params = {{"chart", "sg"}, {"patches", per_run}};
    nr.simulated = true;
    nr.instruments = nlohmann::json::array({{{"id", "meter"}, {"kind", "spectrolino"}}});
    auto e = store.create_execution(nr).execution;
    store.start_execution(e);
    for (int i = 0; i < per_run; i += per_step) {
      store::StepRecord step;
      // Central keys a measurement by (run, step): each keeps its own step name, as one patch a step does.
      step.step = "patch-" + std::to_string(std::min(per_run, i + per_step));
      step.progress = std::min(1.0, static_cast<double>(i + per_step) / per_run);
      for (int j = i; j < std::min(per_run, i + per_step); ++j) {
        store::MeasurementRow m;
        m.step = "patch-" + std::to_string(j + 1);
        m.instrument_id = "meter";
        m.simulated = true;
        m.quantity = "XYZ";
        m.value = value(rng);
        m.unit = "cd/m2";
        m.data = {{"xyz", {value(rng), value(rng), value(rng)}}, {"patch", j + 1}};
        step.measurements.push_back(std::move(m));
      }
      store.commit_step(e, step);
    }
    store.finish_execution(e, protocol::ExecutionStatus::finished_ok, "done", {{"patches", per_run}}, nullptr,
                           "simulated");
  }
  std::cout << "{\"runs\": " << runs << ", \"measurements\": " << static_cast<long long>(runs) * per_run << "}\n";
  return 0;
}
