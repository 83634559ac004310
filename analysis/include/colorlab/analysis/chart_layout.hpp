#pragma once
// The patch grids colorlab can find in a photograph: ColorChecker SG (14 × 10) and ColorChecker 24 (6 × 4).
//
// Grid units: the patch pitch is 1. Patch (column c, row r) covers [c, c + size] × [r, r + size] with size < 1
// (the rest is the dark gap between patches), so its centre is (c + size/2, r + size/2). The chart's "corners" are
// the outer corners of the patch grid — the outer corners of its four corner patches, which is what an operator
// can click on any make of chart — in reading order: top-left (A1 on an SG, patch 1 on a CC24), top-right,
// bottom-right, bottom-left.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace colorlab::analysis {

enum class ChartType {
  sg140,
  cc24
};

// "sg", "sg140", "cc24", "24" (case-insensitive); throws Error(bad_parameter).
ChartType chart_type_from_string(std::string_view name);
std::string_view to_string(ChartType type);  // "sg" / "cc24"

struct ChartLayout {
  ChartType type = ChartType::sg140;
  std::string name;  // "ColorChecker SG"
  int columns = 0, rows = 0;
  double patch_size = 0.8;  // patch side / pitch
  // Patches in the chart's file order: SG A1, A2, …, A10, B1, … (letter = column); CC24 1…24 row by row.
  std::vector<std::string> ids;
  std::vector<int> column, row;  // of each patch, 0-based
  // Expected relative luminance (linear, white ≈ 0.9) where the layout itself fixes it, NaN elsewhere: the SG's
  // neutral border, the CC24's published L*. Used to find which way up the chart is.
  std::vector<double> expected_luminance;
  // Groups of patches that are the same colour (the SG's repeated border white, grey and black).
  std::vector<std::vector<int>> repeated_neutrals;
  // Patches that must get darker in this order in every channel (the CC24's neutral row, white → black).
  std::vector<int> neutral_ramp;

  int size() const { return static_cast<int>(ids.size()); }
  std::optional<int> index_at(int column, int row) const;
  std::optional<int> index_of(std::string_view id) const;
  // Centre of a patch and the four grid corners, in grid units.
  double centre_x(int index) const { return column[static_cast<std::size_t>(index)] + patch_size / 2; }
  double centre_y(int index) const { return row[static_cast<std::size_t>(index)] + patch_size / 2; }
  double grid_width() const { return columns - 1 + patch_size; }
  double grid_height() const { return rows - 1 + patch_size; }
};

const ChartLayout& chart_layout(ChartType type);

}  // namespace colorlab::analysis
