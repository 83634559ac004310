#include "colorlab/campaigns/run_reader.hpp"

#include <optional>
#include <utility>

#include "colorlab/core/error.hpp"

namespace colorlab::campaigns {

using nlohmann::json;

json chart_reference(RunReader& runs, const std::string& run_id) {
  auto run = runs.run(run_id);
  if (!run) {
    throw Error(ErrorClass::not_found, "lab.runs.chart_reference: there is no run " + run_id,
                "give the id of a finished chart-read run (colorlab runs lists them)");
  }
  if (run->campaign != "chart-read") {
    throw Error(ErrorClass::bad_parameter, "lab.runs.chart_reference: run " + run_id + " is a " + run->campaign + " run, not chart-read",
                "give the id of a finished chart-read run");
  }
  if (run->status != "finished_ok") {
    // A partial read would silently leave patches out of the characterization.
    throw Error(ErrorClass::conflict, "lab.runs.chart_reference: chart-read run " + run_id + " is " + run->status + ", not finished_ok",
                "let the chart read finish (or resume it), or run chart-read again");
  }
  json ids = json::array(), lab = json::array(), xyz = json::array(), spectra = json::array();
  std::string illuminant, observer;
  // The reflectance spectra, when every patch has one on one grid (§7.4's black box needs them).
  std::optional<std::pair<double, double>> grid;  // first_nm, step_nm
  std::size_t bands = 0;
  bool spectral = true;
  for (const auto& m : run->measurements) {
    if (m.step.rfind("patch/", 0) != 0) continue;
    const json& d = m.data;
    if (!d.is_object() || !d.contains("id") || !d.contains("Lab") || !d.contains("XYZ") || d["Lab"].size() != 3 || d["XYZ"].size() != 3) {
      throw Error(ErrorClass::bad_data, "lab.runs.chart_reference: run " + run_id + "'s " + m.step + " has no L*a*b* and XYZ",
                  "the run was made by an older chart-read: run chart-read again");
    }
    ids.push_back(d["id"]);
    lab.push_back(d["Lab"]);
    xyz.push_back(d["XYZ"]);
    if (spectral && d.contains("values") && d["values"].is_array() && d.contains("first_nm") && d.contains("step_nm")) {
      const std::pair<double, double> g{d["first_nm"].get<double>(), d["step_nm"].get<double>()};
      if (!grid) {
        grid = g;
        bands = d["values"].size();
      }
      if (g != *grid || d["values"].size() != bands) spectral = false;
      spectra.push_back(d["values"]);
    } else {
      spectral = false;
    }
    illuminant = d.value("illuminant", illuminant);
    observer = d.value("observer", observer);
  }
  if (ids.empty()) {
    throw Error(ErrorClass::bad_data, "lab.runs.chart_reference: chart-read run " + run_id + " holds no patches",
                "run chart-read again");
  }
  json out{{"run_id", run->id},
           {"chart", run->params.value("chart", std::string("sg"))},
           {"illuminant", illuminant},
           {"observer", observer},
           {"simulated", run->simulated},
           {"ids", ids},
           {"Lab", lab},
           {"XYZ", xyz}};
  if (spectral && grid && bands >= 3) {
    json wavelengths = json::array();
    for (std::size_t k = 0; k < bands; ++k) wavelengths.push_back(grid->first + grid->second * static_cast<double>(k));
    out["wavelengths"] = wavelengths;
    out["spectra"] = spectra;
  }
  return out;
}

}  // namespace colorlab::campaigns
