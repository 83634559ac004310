#include "colorlab/campaigns/chart_plan.hpp"

#include "colorlab/analysis/chart_layout.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/drivers/serpentine.hpp"

namespace colorlab::campaigns {

using nlohmann::json;

json chart_plan(const json& options) {
  if (!options.is_object()) throw Error(ErrorClass::script_error, "lab.chart.plan takes a table {chart=, first_x_mm=, first_y_mm=, pitch_mm=}");
  auto number = [&](const char* key, double fallback, double lo, double hi) {
    if (!options.contains(key)) return fallback;
    const auto& v = options[key];
    if (!v.is_number() || !(v.get<double>() >= lo && v.get<double>() <= hi)) {
      throw Error(ErrorClass::script_error, std::string("lab.chart.plan: ") + key + " must be a number from " +
                                                std::to_string(lo) + " to " + std::to_string(hi));
    }
    return v.get<double>();
  };
  analysis::ChartType type;
  try {
    type = analysis::chart_type_from_string(options.value("chart", std::string("sg")));
  } catch (const Error& e) {
    throw Error(ErrorClass::script_error, std::string("lab.chart.plan: ") + e.what());
  }
  const auto& layout = analysis::chart_layout(type);
  drivers::ChartLayout table;
  const double pitch = number("pitch_mm", 19.0, 1, 100);
  table.origin_x_mm = number("first_x_mm", 31.2, 0, 310);
  table.origin_y_mm = number("first_y_mm", 29.45, 0, 230);
  // Serpentine numbering is strip by strip: a strip is a column when the chart's file order runs
  // down the columns (SG: A1, A2, …), a row when it runs along the rows (CC24: 1, 2, …).
  const bool column_strips = layout.size() > 1 && layout.column[0] == layout.column[1];
  if (column_strips) {
    table.step_y_mm = pitch;
    table.pass_x_mm = pitch;
    table.patches_per_strip = layout.rows;
    table.strips = layout.columns;
  } else {
    table.step_x_mm = pitch;
    table.pass_y_mm = pitch;
    table.patches_per_strip = layout.columns;
    table.strips = layout.rows;
  }
  table.patch_count = layout.size();
  std::vector<std::vector<drivers::PatchVisit>> rows;
  try {
    rows = drivers::serpentine_rows(table);
  } catch (const Error& e) {
    throw Error(ErrorClass::script_error, std::string("lab.chart.plan: ") + e.what(),
                "place the chart so every patch is on the table (X 0–310 mm, Y 0–230 mm)");
  }
  json out_rows = json::array();
  for (const auto& row : rows) {
    json r = json::array();
    for (const auto& p : row) {
      r.push_back({{"index", p.index}, {"id", layout.ids[static_cast<std::size_t>(p.index)]}, {"x_mm", p.x_mm}, {"y_mm", p.y_mm}});
    }
    out_rows.push_back(r);
  }
  return json{{"chart", std::string(analysis::to_string(type))}, {"patches", layout.size()}, {"rows", out_rows}};
}

}  // namespace colorlab::campaigns
