// lab.analysis.floor_luminance apart from the photograph's capture: pure analysis, so the campaign
// script fuzz target links it without the camera drivers.
#include <algorithm>
#include <map>
#include <utility>
#include <vector>

#include "colorlab/analysis/floor_luminance.hpp"
#include "colorlab/campaigns/floor_photograph.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::campaigns {

using nlohmann::json;

json floor_luminance(const json& photo, const json& calibration, const json& options) {
  auto bad_script = [](const std::string& what) { return Error(ErrorClass::script_error, "lab.analysis.floor_luminance: " + what); };
  if (!photo.is_object() || !photo.contains("spots") || !photo.contains("subsets") || !photo.contains("width")) {
    throw bad_script("the first argument is lab.camera.photograph_floor's result");
  }
  const json o = options.is_object() ? options : json::object();
  const int degree = o.value("degree", 2);
  if (degree < 0 || degree > 4) throw bad_script("degree must be from 0 to 4");
  const auto& subsets = photo["subsets"];
  std::size_t at = subsets.size() - 1;
  if (o.contains("subset")) {
    const auto it = std::find(subsets.begin(), subsets.end(), o["subset"]);
    if (it == subsets.end()) throw bad_script("subset " + o["subset"].dump() + " is not one of the photograph's averages " + subsets.dump());
    at = static_cast<std::size_t>(it - subsets.begin());
  }
  std::map<std::pair<int, int>, const json*> by_spot;
  for (const auto& s : photo["spots"]) by_spot[{s["row"].get<int>(), s["col"].get<int>()}] = &s;
  if (!calibration.is_array() || calibration.empty()) throw bad_script("calibration must list {row =, col =, luminance =} readings");
  std::vector<analysis::FlatFieldSample> cal;
  json used = json::array();
  for (const auto& c : calibration) {
    if (!c.is_object() || !c.contains("row") || !c.contains("col") || !c.contains("luminance") || !c["luminance"].is_number()) {
      throw bad_script("each calibration reading is {row =, col =, luminance =}");
    }
    const auto it = by_spot.find({c["row"].get<int>(), c["col"].get<int>()});
    if (it == by_spot.end()) throw bad_script("the photograph did not sample calibration spot row " + c["row"].dump() + ", col " + c["col"].dump());
    const json& s = *it->second;
    cal.push_back({s["px"][0].get<double>(), s["px"][1].get<double>(), s["signal"][at].get<double>(), c["luminance"].get<double>()});
  }
  const auto fit = analysis::fit_flat_field(cal, photo["width"].get<int>(), photo["height"].get<int>(), degree);
  for (std::size_t i = 0; i < cal.size(); ++i) {
    used.push_back({
        {"row", calibration[i]["row"]},
        {"col", calibration[i]["col"]},
        {"luminance", cal[i].luminance},
        {"fitted", fit.luminance(cal[i].x_px, cal[i].y_px, cal[i].signal)},
        {"residual_pct", fit.residual_pct[i]},
    });
  }
  json spots = json::array();
  for (const auto& s : photo["spots"]) {
    const double x = s["px"][0].get<double>(), y = s["px"][1].get<double>();
    spots.push_back({
        {"row", s["row"]},
        {"col", s["col"]},
        {"luminance", fit.luminance(x, y, s["signal"][at].get<double>())},
        {"gain", fit.gain(x, y)},
    });
  }
  return json{
      {"degree", fit.degree},
      {"frames", subsets[at]},
      {"coefficients", fit.coefficients},
      {"centre_px", {fit.centre_x, fit.centre_y}},
      {"radius_px", fit.radius},
      {"spots", spots},
      {"calibration", used},
  };
}

}  // namespace colorlab::campaigns
