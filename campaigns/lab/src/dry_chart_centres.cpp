#include "dry_chart_centres.hpp"

#include <algorithm>
#include <cmath>

#include "colorlab/analysis/chart_attitude.hpp"
#include "colorlab/analysis/chart_layout.hpp"

namespace colorlab::campaigns::detail {

using nlohmann::json;

json dry_chart_centres(const json& placement, const std::string& chart) {
  const auto& layout = analysis::chart_layout(analysis::chart_type_from_string(chart));
  const auto number = [&](const char* key, double fallback) {
    return placement.is_object() && placement.contains(key) && placement[key].is_number() ? placement[key].get<double>() : fallback;
  };
  // The simulator's convention, from the one function both use (chart_attitude.hpp): the dry run's poses lean the
  // way the simulated lab's hands will lean them.
  const Eigen::Matrix3d R =
      analysis::chart_attitude_rotation(number("rotation_deg", 0), number("tilt_deg", 0), number("swing_deg", 0));
  const double fill = std::clamp(number("fill", 0.8), 0.05, 1.0);
  // A 50 mm lens on a 22.5 mm wide sensor; the chart's distance (in its grid units) makes it fill `fill` of the height.
  const double f = kDryPhotoWidth * 50.0 / 22.5, W = layout.grid_width(), H = layout.grid_height();
  const double distance = f * H / (fill * kDryPhotoHeight);
  const double t[3] = {number("shift_x", 0) * kDryPhotoWidth * distance / f, number("shift_y", 0) * kDryPhotoHeight * distance / f, distance};
  json observed = json::array();
  for (int k = 0; k < layout.size(); ++k) {
    const double X = layout.centre_x(k) - W / 2, Y = layout.centre_y(k) - H / 2;
    double c[3];
    for (int i = 0; i < 3; ++i) c[i] = R(i, 0) * X + R(i, 1) * Y + t[i];
    observed.push_back({{"id", layout.ids[static_cast<std::size_t>(k)]},
                        {"x", f * c[0] / c[2] + (kDryPhotoWidth - 1) / 2.0},
                        {"y", f * c[1] / c[2] + (kDryPhotoHeight - 1) / 2.0}});
  }
  return observed;
}

}  // namespace colorlab::campaigns::detail
