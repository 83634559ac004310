#pragma once
// What a campaign may read of earlier runs (characterize-camera takes its reference colours from a
// chart-read run). Read-only, and an interface: the daemon answers it from its store, so the engine
// stays free of SQLite.
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace colorlab::campaigns {

struct StoredMeasurement {
  std::string step;
  std::string instrument_id;
  std::string quantity;
  std::optional<double> value;
  std::string unit;
  nlohmann::json data;
};

struct StoredRun {
  std::string id;
  std::string campaign;
  std::string status;  // "finished_ok", "running", …
  bool simulated = false;
  nlohmann::json params;
  std::vector<StoredMeasurement> measurements;
};

class RunReader {
 public:
  virtual ~RunReader() = default;
  // The run with its measurements, or nullopt when there is none with that id.
  virtual std::optional<StoredRun> run(const std::string& run_id) = 0;
};

// lab.runs.chart_reference(run_id): the reference colours of a finished chart-read run,
// {run_id, chart, illuminant, observer, simulated, ids, Lab = [[L, a, b], …], XYZ = [[X, Y, Z], …],
// wavelengths = [nm, …], spectra = [[reflectance per band], …]} in the run's patch order; wavelengths
// and spectra only when every patch was stored with its spectrum on one grid (older runs were not). Error(not_found) for an unknown run, Error(bad_parameter) for a run of
// another campaign, Error(conflict) for one that did not finish.
nlohmann::json chart_reference(RunReader& runs, const std::string& run_id);

}  // namespace colorlab::campaigns
