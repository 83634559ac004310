#include "chart_location_json.hpp"

#include <cmath>
#include <string>

namespace colorlab::daemon {

namespace ca = analysis;
using nlohmann::json;

namespace {

// As the CLI's table printer: numbers as doubles, NaN and infinities as null.
json number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }
const char* yes_no(bool b) { return b ? "yes" : "no"; }

}  // namespace

json chart_location_json(const ca::ChartLocation& loc, double value_scale) {
  std::string notes;
  for (const auto& n : loc.notes) notes += (notes.empty() ? "" : "; ") + n;
  json chart{{"chart", std::string(ca::to_string(loc.type))},
             {"confidence", number(loc.confidence)},
             {"rotation_deg", number(static_cast<double>(loc.rotation_deg))},
             {"from_corners", yes_no(loc.from_corners)},
             {"patches_detected", number(static_cast<double>(loc.patches_detected))},
             {"reprojection_rms_px", number(loc.reprojection_rms_px)},
             {"orientation_margin", number(loc.orientation_margin)},
             {"check", loc.check.method},
             {"check_passed", yes_no(loc.check.passed)},
             {"check_worst_pct", number(loc.check.worst_disagreement * 100)},
             {"check_worst_patch", loc.check.worst_patch},
             {"gradient_x_pct", number(loc.check.gradient_x * 100)},
             {"gradient_y_pct", number(loc.check.gradient_y * 100)},
             {"check_detail", loc.check.detail},
             {"notes", notes}};
  json corners = json::array();
  const char* names[4] = {"top_left", "top_right", "bottom_right", "bottom_left"};
  for (std::size_t i = 0; i < 4; ++i) corners.push_back({{"corner", names[i]}, {"x", number(loc.corners[i].x)}, {"y", number(loc.corners[i].y)}});
  json patches = json::array();
  for (const auto& p : loc.patches) {
    json row{{"id", p.id},
             {"x", number(p.centre.x)},
             {"y", number(p.centre.y)},
             {"detected", yes_no(p.detected)},
             {"region_x", number(static_cast<double>(p.region.x))},
             {"region_y", number(static_cast<double>(p.region.y))},
             {"region_width", number(static_cast<double>(p.region.width))},
             {"region_height", number(static_cast<double>(p.region.height))}};
    std::size_t used = 0, total = 0;
    const char* rgb[3] = {"R", "G", "B"};
    for (int c = 0; c < p.channels; ++c) {
      const auto& v = p.value[static_cast<std::size_t>(c)];
      row[p.channels == 3 ? rgb[c] : "value"] = number(v.value / value_scale);
      used += v.used;
      total += v.total;
    }
    row["used"] = number(static_cast<double>(used));
    row["total"] = number(static_cast<double>(total));
    patches.push_back(std::move(row));
  }
  return json{{"chart", json::array({chart})}, {"corners", corners}, {"patches", patches}};
}

}  // namespace colorlab::daemon
