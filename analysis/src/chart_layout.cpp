#include "colorlab/analysis/chart_layout.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <string>

#include "colorlab/core/error.hpp"

namespace colorlab::analysis {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double luminance_of_lstar(double L) {
  const double f = (L + 16.0) / 116.0;
  return L > 8.0 ? f * f * f : L / 903.3;
}

ChartLayout make_sg() {
  ChartLayout l;
  l.type = ChartType::sg140;
  l.name = "ColorChecker SG";
  l.columns = 14;
  l.rows = 10;
  l.patch_size = 15.0 / 19.0;  // 15 mm patches on a 19 mm pitch
  for (int c = 0; c < l.columns; ++c)
    for (int r = 0; r < l.rows; ++r) {
      l.ids.push_back(std::string(1, static_cast<char>('A' + c)) + std::to_string(r + 1));
      l.column.push_back(c);
      l.row.push_back(r);
    }
  l.expected_luminance.assign(l.ids.size(), kNaN);
  // The SG's border repeats three neutrals: W(hite, L* 96.5), G(rey, L* 49.7), K (black, L* 6.5). Top and bottom
  // rows read alike left to right; the left and right columns differ, so the border alone fixes the orientation.
  const std::string top = "WGKWGKWGKWGKGW", left = "WKGWKGWKGW", right = "WGKWGKWGKW";
  auto cls = [&](int c, int r) -> char {
    if (r == 0 || r == l.rows - 1) return top[static_cast<std::size_t>(c)];
    if (c == 0) return left[static_cast<std::size_t>(r)];
    if (c == l.columns - 1) return right[static_cast<std::size_t>(r)];
    return 0;
  };
  std::vector<int> white, grey, black;
  for (int i = 0; i < l.size(); ++i) {
    const char k = cls(l.column[static_cast<std::size_t>(i)], l.row[static_cast<std::size_t>(i)]);
    if (k == 'W') white.push_back(i), l.expected_luminance[static_cast<std::size_t>(i)] = luminance_of_lstar(96.5);
    if (k == 'G') grey.push_back(i), l.expected_luminance[static_cast<std::size_t>(i)] = luminance_of_lstar(49.7);
    if (k == 'K') black.push_back(i), l.expected_luminance[static_cast<std::size_t>(i)] = luminance_of_lstar(6.5);
  }
  l.repeated_neutrals = {white, grey, black};
  return l;
}

ChartLayout make_cc24() {
  ChartLayout l;
  l.type = ChartType::cc24;
  l.name = "ColorChecker 24";
  l.columns = 6;
  l.rows = 4;
  l.patch_size = 0.9;
  // X-Rite's published L* (D50) of the 24 patches, row by row from dark skin to black.
  const double lstar[24] = {38.0, 65.7, 49.9, 43.1, 55.1, 70.7, 62.7, 40.0, 51.1, 30.3, 72.5, 71.9,
                            28.8, 55.3, 42.1, 81.7, 51.9, 51.0, 96.5, 81.3, 66.8, 50.9, 35.7, 20.5};
  for (int r = 0; r < l.rows; ++r)
    for (int c = 0; c < l.columns; ++c) {
      l.ids.push_back(std::to_string(r * l.columns + c + 1));
      l.column.push_back(c);
      l.row.push_back(r);
      l.expected_luminance.push_back(luminance_of_lstar(lstar[r * l.columns + c]));
    }
  l.neutral_ramp = {18, 19, 20, 21, 22, 23};
  return l;
}

}  // namespace

ChartType chart_type_from_string(std::string_view name) {
  std::string n(name);
  std::transform(n.begin(), n.end(), n.begin(), [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  if (n == "sg" || n == "sg140" || n == "colorchecker-sg") return ChartType::sg140;
  if (n == "cc24" || n == "24" || n == "colorchecker24") return ChartType::cc24;
  throw Error(ErrorClass::bad_parameter, "unknown chart '" + std::string(name) + "'", "use sg (ColorChecker SG) or cc24");
}

std::string_view to_string(ChartType type) { return type == ChartType::sg140 ? "sg" : "cc24"; }

std::optional<int> ChartLayout::index_at(int c, int r) const {
  if (c < 0 || c >= columns || r < 0 || r >= rows) return std::nullopt;
  return type == ChartType::sg140 ? c * rows + r : r * columns + c;
}

std::optional<int> ChartLayout::index_of(std::string_view id) const {
  for (std::size_t i = 0; i < ids.size(); ++i)
    if (ids[i] == id) return static_cast<int>(i);
  return std::nullopt;
}

const ChartLayout& chart_layout(ChartType type) {
  static const ChartLayout sg = make_sg(), cc24 = make_cc24();
  return type == ChartType::sg140 ? sg : cc24;
}

}  // namespace colorlab::analysis
