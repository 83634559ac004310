#include <cmath>
#include <numbers>

#include "colorlab/verify/cabinet.hpp"

namespace colorlab::verify {
namespace {

// Factor from a point to the rectangle [0, a] × [0, b] at height h directly above one of its corners
// (e.g. Howell's catalogue of configuration factors, case "differential element to parallel rectangle").
// Odd in a and in b, which is what lets rectangles anywhere be summed from signed corner rectangles.
double corner(double a, double b, double h) {
  const double A = a / h, B = b / h;
  const double sa = std::sqrt(1.0 + A * A), sb = std::sqrt(1.0 + B * B);
  return (A / sa * std::atan(B / sa) + B / sb * std::atan(A / sb)) / (2.0 * std::numbers::pi);
}

}  // namespace

double form_factor(const CabinetEmitter& e, double height_mm, double x_mm, double y_mm) {
  const double x1 = e.x_mm - e.length_mm / 2 - x_mm, x2 = e.x_mm + e.length_mm / 2 - x_mm;
  const double y1 = e.y_mm - e.width_mm / 2 - y_mm, y2 = e.y_mm + e.width_mm / 2 - y_mm;
  return corner(x2, y2, height_mm) - corner(x1, y2, height_mm) - corner(x2, y1, height_mm) +
         corner(x1, y1, height_mm);
}

}  // namespace colorlab::verify
