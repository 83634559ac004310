// lab.analysis.calibrate_lens apart from the photographs' capture: pure analysis, as floor_luminance_fit.cpp.
#include "colorlab/campaigns/lens_calibration.hpp"

#include <string>
#include <vector>

#include "colorlab/analysis/chart_layout.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/verify/lens_calibration.hpp"

namespace colorlab::campaigns {

using nlohmann::json;

json calibrate_lens(const json& photographs, const json& options) {
  auto bad = [](const std::string& what) { return Error(ErrorClass::script_error, "lab.analysis.calibrate_lens: " + what); };
  if (!photographs.is_array()) throw bad("the first argument lists the photographs (lab.camera.photograph_chart's format answers)");
  const json o = options.is_object() ? options : json::object();
  const auto text = [&](const char* key, bool required) {
    if (!o.contains(key) || o[key].is_null()) {
      if (required) throw bad(std::string("options.") + key + " is required (a string)");
      return std::string();
    }
    if (!o[key].is_string()) throw bad(std::string("options.") + key + " must be a string");
    return o[key].get<std::string>();
  };
  verify::LensIdentity who{text("camera", true), text("lens", true), text("focus", false), text("date", false), std::nullopt};
  if (o.contains("focal_length_mm") && !o["focal_length_mm"].is_null()) {
    if (!o["focal_length_mm"].is_number()) throw bad("options.focal_length_mm must be a number");
    who.focal_length_mm = o["focal_length_mm"].get<double>();
  }
  const std::string by = o.contains("by") ? text("by", true) : "lab.analysis.calibrate_lens";

  std::string chart;
  int width = 0, height = 0;
  std::vector<verify::ObservedCentres> centres;
  for (std::size_t i = 0; i < photographs.size(); ++i) {
    const json& p = photographs[i];
    const std::string which = "photograph " + std::to_string(i + 1);
    if (!p.is_object() || !p.contains("observed_px") || !p["observed_px"].is_array() || !p.contains("width") || !p.contains("height") ||
        !p["width"].is_number_integer() || !p["height"].is_number_integer())
      throw bad(which + " has no observed_px, width and height (photograph_chart's format answer, taken with centres = true)");
    const std::string c = p.value("chart", std::string("sg"));
    const int w = p["width"].get<int>(), h = p["height"].get<int>();
    if (i == 0) chart = c, width = w, height = h;
    if (c != chart) throw bad(which + " is of the " + c + ", the first of the " + chart);
    if (w != width || h != height)
      throw Error(ErrorClass::bad_parameter,
                  "lab.analysis.calibrate_lens: " + which + " is " + std::to_string(w) + " × " + std::to_string(h) + ", the first " +
                      std::to_string(width) + " × " + std::to_string(height),
                  "one calibration holds for one photograph size: keep the camera's settings throughout");
    // By patch id into the layout's order (patches not detected stay empty).
    const analysis::ChartLayout& layout = analysis::chart_layout(analysis::chart_type_from_string(c));
    verify::ObservedCentres observed(static_cast<std::size_t>(layout.size()));
    for (const auto& at : p["observed_px"]) {
      if (!at.is_object() || !at.contains("id") || !at["id"].is_string() || !at.contains("x") || !at["x"].is_number() ||
          !at.contains("y") || !at["y"].is_number())
        throw bad(which + ": observed_px holds {id, x, y} per detected patch");
      const auto k = layout.index_of(at["id"].get<std::string>());
      if (!k) throw bad(which + ": the " + layout.name + " has no patch " + at["id"].get<std::string>());
      observed[static_cast<std::size_t>(*k)] = std::array{at["x"].get<double>(), at["y"].get<double>()};
    }
    centres.push_back(std::move(observed));
  }
  const verify::LensCalibration l = verify::calibrate_lens_from_chart(chart.empty() ? "sg" : chart, centres, width, height, who, by);
  json out = verify::lens_to_json(l);
  out["toml"] = verify::lens_to_toml(l);
  return out;
}

}  // namespace colorlab::campaigns
