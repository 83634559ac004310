#include "dry_chart_centres.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "colorlab/analysis/chart_layout.hpp"

namespace colorlab::campaigns::detail {

using nlohmann::json;

json dry_chart_centres(const json& placement, const std::string& chart) {
  const auto& layout = analysis::chart_layout(analysis::chart_type_from_string(chart));
  const auto number = [&](const char* key, double fallback) {
    return placement.is_object() && placement.contains(key) && placement[key].is_number() ? placement[key].get<double>() : fallback;
  };
  const double deg = std::numbers::pi / 180;
  // Negated as the simulator's chart_pose.cpp does: a positive tilt leans the top edge away, a positive swing the right
  // edge (camera coordinates: y down, z along the view).
  const double rz = number("rotation_deg", 0) * deg, rx = -number("tilt_deg", 0) * deg, ry = -number("swing_deg", 0) * deg;
  const double fill = std::clamp(number("fill", 0.8), 0.05, 1.0);
  // R = Rz · Rx(−tilt) · Ry(−swing), as the simulator poses its chart (rotation in the image plane, tilt, swing).
  const double cz = std::cos(rz), sz = std::sin(rz), cx = std::cos(rx), sx = std::sin(rx), cy = std::cos(ry), sy = std::sin(ry);
  const double Rzx[3][3] = {{cz, -sz * cx, sz * sx}, {sz, cz * cx, -cz * sx}, {0, sx, cx}};
  const double Ry[3][3] = {{cy, 0, sy}, {0, 1, 0}, {-sy, 0, cy}};
  double R[3][3] = {};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) R[i][j] += Rzx[i][k] * Ry[k][j];
  // A 50 mm lens on a 22.5 mm wide sensor; the chart's distance (in its grid units) makes it fill `fill` of the height.
  const double f = kDryPhotoWidth * 50.0 / 22.5, W = layout.grid_width(), H = layout.grid_height();
  const double distance = f * H / (fill * kDryPhotoHeight);
  const double t[3] = {number("shift_x", 0) * kDryPhotoWidth * distance / f, number("shift_y", 0) * kDryPhotoHeight * distance / f, distance};
  json observed = json::array();
  for (int k = 0; k < layout.size(); ++k) {
    const double X = layout.centre_x(k) - W / 2, Y = layout.centre_y(k) - H / 2;
    double c[3];
    for (int i = 0; i < 3; ++i) c[i] = R[i][0] * X + R[i][1] * Y + t[i];
    observed.push_back({{"id", layout.ids[static_cast<std::size_t>(k)]},
                        {"x", f * c[0] / c[2] + (kDryPhotoWidth - 1) / 2.0},
                        {"y", f * c[1] / c[2] + (kDryPhotoHeight - 1) / 2.0}});
  }
  return observed;
}

}  // namespace colorlab::campaigns::detail
