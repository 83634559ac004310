#pragma once
// A located chart as JSON, in the shape `colorlab analyze locate-chart --json` prints (tables `chart`, `corners`,
// `patches`, one object per row), so a script reads the daemon's answer and the offline tool's alike. The
// integration test holds the two to each other on the same photograph.
#include <nlohmann/json.hpp>

#include "colorlab/analysis/chart_locate.hpp"

namespace colorlab::daemon {

// `value_scale`: patch values are divided by it (a photo whose samples were scaled from the blob's counts).
nlohmann::json chart_location_json(const analysis::ChartLocation& location, double value_scale = 1);

}  // namespace colorlab::daemon
