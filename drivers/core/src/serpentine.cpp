#include "colorlab/drivers/serpentine.hpp"

#include <cmath>
#include <string>

#include "colorlab/core/error.hpp"

namespace colorlab::drivers {

std::vector<std::vector<PatchVisit>> serpentine_rows(const ChartLayout& c) {
  if (c.patches_per_strip < 1 || c.strips < 1) {
    throw Error(ErrorClass::bad_parameter, "chart layout needs at least one strip of one patch");
  }
  int total = c.patch_count > 0 ? c.patch_count : c.patches_per_strip * c.strips;
  if (total > c.patches_per_strip * c.strips) {
    throw Error(ErrorClass::bad_parameter, "chart layout has " + std::to_string(total) + " patches but only " +
                                               std::to_string(c.patches_per_strip * c.strips) + " positions");
  }
  auto visit = [&](int strip, int patch) {
    PatchVisit v;
    v.index = strip * c.patches_per_strip + patch;
    v.x_mm = c.origin_x_mm + patch * c.step_x_mm + strip * c.pass_x_mm;
    v.y_mm = c.origin_y_mm + patch * c.step_y_mm + strip * c.pass_y_mm;
    if (v.x_mm < 0 || v.x_mm > 310.0 || v.y_mm < 0 || v.y_mm > 230.0) {
      throw Error(ErrorClass::bad_parameter, "patch " + std::to_string(v.index) + " at (" + std::to_string(v.x_mm) + ", " +
                                                 std::to_string(v.y_mm) + ") mm is off the table (0–310 × 0–230 mm)");
    }
    return v;
  };
  std::vector<std::vector<PatchVisit>> rows;
  const bool along_strips = std::abs(c.step_x_mm) >= std::abs(c.pass_x_mm);
  const int outer = along_strips ? c.strips : c.patches_per_strip;
  const int inner = along_strips ? c.patches_per_strip : c.strips;
  for (int o = 0; o < outer; ++o) {
    std::vector<PatchVisit> row;
    for (int k = 0; k < inner; ++k) {
      int i = (o % 2 == 0) ? k : inner - 1 - k;
      int strip = along_strips ? o : i;
      int patch = along_strips ? i : o;
      if (strip * c.patches_per_strip + patch >= total) continue;
      row.push_back(visit(strip, patch));
    }
    if (!row.empty()) rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace colorlab::drivers
