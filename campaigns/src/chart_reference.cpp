#include "colorlab/campaigns/run_reader.hpp"

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
  json ids = json::array(), lab = json::array(), xyz = json::array();
  std::string illuminant, observer;
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
    illuminant = d.value("illuminant", illuminant);
    observer = d.value("observer", observer);
  }
  if (ids.empty()) {
    throw Error(ErrorClass::bad_data, "lab.runs.chart_reference: chart-read run " + run_id + " holds no patches",
                "run chart-read again");
  }
  return json{{"run_id", run->id},
              {"chart", run->params.value("chart", std::string("sg"))},
              {"illuminant", illuminant},
              {"observer", observer},
              {"simulated", run->simulated},
              {"ids", ids},
              {"Lab", lab},
              {"XYZ", xyz}};
}

}  // namespace colorlab::campaigns
