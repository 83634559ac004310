#pragma once
// Where each patch of a chart lies on the SpectroScan table and in which order to visit them:
// the chart's own layout (analysis/chart_layout: ids, columns, rows) placed on the table by the
// centre of its first patch and the patch pitch, visited in the table's serpentine rows
// (drivers/serpentine). Pure: `lab.chart.plan{...}` in a campaign script.
#include <nlohmann/json.hpp>

namespace colorlab::campaigns {

// options: {chart = "sg"|"cc24", first_x_mm, first_y_mm, pitch_mm}; columns run along +X, rows along +Y.
// Returns {chart, patches, rows = [[{index, id, x_mm, y_mm}, ...], ...]} with `index` the 0-based
// position in the chart's file order. Throws Error{script_error} for bad options or a patch off the table.
nlohmann::json chart_plan(const nlohmann::json& options);

}  // namespace colorlab::campaigns
