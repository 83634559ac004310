#pragma once
// Chart geometry on the SpectroScan table and the serpentine visiting order (Argyll ss.c): rows run
// along whichever of the patch step or the strip pass moves further in X, alternating direction,
// so the head never travels back across the chart between rows.
#include <vector>

namespace colorlab::drivers {

struct ChartLayout {
  double origin_x_mm = 0, origin_y_mm = 0;  // centre of patch 0
  double step_x_mm = 0, step_y_mm = 0;      // patch i → i+1 within a strip
  double pass_x_mm = 0, pass_y_mm = 0;      // strip s → s+1
  int patches_per_strip = 0;
  int strips = 0;
  int patch_count = 0;  // 0 = patches_per_strip × strips; patches are numbered strip by strip
};

struct PatchVisit {
  int index = 0;  // patch number in the chart's own order
  double x_mm = 0, y_mm = 0;
};

// Rows in visiting order; throws Error{bad_parameter} for an empty layout or a patch off the
// table (X 0–310 mm, Y 0–230 mm).
std::vector<std::vector<PatchVisit>> serpentine_rows(const ChartLayout& layout);

}  // namespace colorlab::drivers
