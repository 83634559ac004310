// The dry run's picture of a chart the operator posed (dry_chart_centres.hpp) leans the way the lens-calibration
// campaign's prompts say and the simulated lab's hands lean it (chart_attitude.hpp): checked by what a pinhole must
// show, not by the rotation it is built with — a chart tilted top-away photographs its top row narrower than its
// bottom row, swung right-away its right column shorter than its left, turned clockwise its top row sloping down to
// the right; square-on and centred, it is symmetric about the frame's centre and fills `fill` of the frame's height.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "colorlab/analysis/chart_layout.hpp"
#include "dry_chart_centres.hpp"

namespace colorlab::campaigns::detail {
namespace {

using nlohmann::json;

struct Seen {
  double top_span, bottom_span, left_span, right_span, top_slope, cx, cy, height;
};

// The outer rows' and columns' extents on the dry photograph.
Seen seen(const json& placement) {
  const auto& layout = analysis::chart_layout(analysis::ChartType::sg140);
  const json c = dry_chart_centres(placement, "sg");
  double ymin = 1e9, ymax = -1e9, xmin = 1e9, xmax = -1e9;
  for (int k = 0; k < layout.size(); ++k) {
    ymin = std::min(ymin, layout.centre_y(k)), ymax = std::max(ymax, layout.centre_y(k));
    xmin = std::min(xmin, layout.centre_x(k)), xmax = std::max(xmax, layout.centre_x(k));
  }
  std::map<std::string, std::pair<double, double>> at;  // corner patch → its image position
  double sx = 0, sy = 0, top = 1e9, bottom = -1e9;
  for (int k = 0; k < layout.size(); ++k) {
    const json& at_k = c[static_cast<std::size_t>(k)];
    const double x = at_k["x"].get<double>(), y = at_k["y"].get<double>();
    sx += x, sy += y;
    const bool t = layout.centre_y(k) == ymin, b = layout.centre_y(k) == ymax, l = layout.centre_x(k) == xmin, r = layout.centre_x(k) == xmax;
    if (t && l) at["tl"] = {x, y};
    if (t && r) at["tr"] = {x, y};
    if (b && l) at["bl"] = {x, y};
    if (b && r) at["br"] = {x, y};
    top = std::min(top, y), bottom = std::max(bottom, y);
  }
  const auto d = [&](const char* a, const char* b) { return std::hypot(at[a].first - at[b].first, at[a].second - at[b].second); };
  return {d("tl", "tr"), d("bl", "br"), d("tl", "bl"), d("tr", "br"), (at["tr"].second - at["tl"].second) / (at["tr"].first - at["tl"].first),
          sx / layout.size(), sy / layout.size(), bottom - top};
}

TEST(DryChartCentres, APosedChartLeansAsThePromptSays) {
  const Seen square = seen({{"fill", 0.6}});
  EXPECT_NEAR(square.top_span, square.bottom_span, 1e-9);
  EXPECT_NEAR(square.left_span, square.right_span, 1e-9);
  EXPECT_NEAR(square.cx, (kDryPhotoWidth - 1) / 2.0, 1e-9);
  EXPECT_NEAR(square.cy, (kDryPhotoHeight - 1) / 2.0, 1e-9);
  // The patch centres span the grid less one patch: fill · height · (rows − 1) / (grid height).
  const auto& layout = analysis::chart_layout(analysis::ChartType::sg140);
  EXPECT_NEAR(square.height, 0.6 * kDryPhotoHeight * (layout.grid_height() - layout.patch_size) / layout.grid_height(), 1e-6);

  const Seen tilted = seen({{"tilt_deg", 20}, {"fill", 0.6}});
  EXPECT_LT(tilted.top_span, tilted.bottom_span) << "a positive tilt leans the top edge away";
  const Seen back = seen({{"tilt_deg", -20}, {"fill", 0.6}});
  EXPECT_GT(back.top_span, back.bottom_span);
  const Seen swung = seen({{"swing_deg", 20}, {"fill", 0.6}});
  EXPECT_LT(swung.right_span, swung.left_span) << "a positive swing leans the right edge away";
  const Seen turned = seen({{"rotation_deg", 5}, {"fill", 0.6}});
  EXPECT_NEAR(turned.top_slope, std::tan(5 * M_PI / 180), 1e-9) << "a positive rotation turns the chart clockwise (y down)";
  const Seen shifted = seen({{"shift_x", 0.1}, {"shift_y", -0.1}, {"fill", 0.6}});
  EXPECT_NEAR(shifted.cx - square.cx, 0.1 * kDryPhotoWidth, 1e-6);
  EXPECT_NEAR(shifted.cy - square.cy, -0.1 * kDryPhotoHeight, 1e-6);
}

}  // namespace
}  // namespace colorlab::campaigns::detail
