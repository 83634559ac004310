// The analytic form factor of a ceiling emitter (verify::form_factor) against truths computed another way:
// a numerical integration of the point-to-area kernel cos·cos/(π r²) over the emitter, the closed form of an
// infinitely long strip (the 2-D crossed-strings result), the small-emitter limit, and additivity.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "colorlab/verify/cabinet.hpp"

namespace colorlab::verify {
namespace {

// F = (1/π) ∫∫ h² / r⁴ dA for parallel planes (cos θ = h/r at both ends), midpoint rule.
double integrated(const CabinetEmitter& e, double h, double x, double y, int nx, int ny) {
  const double dx = e.length_mm / nx, dy = e.width_mm / ny;
  double sum = 0;
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      const double px = e.x_mm - e.length_mm / 2 + (i + 0.5) * dx - x, py = e.y_mm - e.width_mm / 2 + (j + 0.5) * dy - y;
      const double r2 = px * px + py * py + h * h;
      sum += h * h / (r2 * r2);
    }
  }
  return sum * dx * dy / std::numbers::pi;
}

TEST(FormFactor, AgreesWithANumericalIntegrationOverTheEmitterAnywhereOnTheFloor) {
  const CabinetEmitter e{"D65", 600, 100, 1000, 100, 1};
  // Under the panel, beside it, in a back corner, and far outside its footprint.
  for (auto [x, y] : {std::pair{600.0, 100.0}, {30.0, 27.0}, {1170.0, 567.0}, {950.0, 300.0}, {600.0, 0.0}}) {
    const double truth = integrated(e, 600.0, x, y, 2000, 200);
    // The midpoint rule's error falls as the cell size squared: at 0.5 mm cells it is ~1e-6 relative.
    EXPECT_NEAR(form_factor(e, 600.0, x, y) / truth, 1.0, 1e-5) << x << ", " << y;
  }
}

TEST(FormFactor, ALongStripGivesTheTwoDimensionalClosedForm) {
  // An infinitely long strip of width w centred above the point: F = sin φ, tan φ = (w/2)/h (Hottel's
  // crossed strings for a strip seen from a line element).
  const double w = 100.0, h = 600.0;
  const CabinetEmitter strip{"D65", 0, 0, 1e9, w, 1};
  const double phi = std::atan(w / 2 / h);
  EXPECT_NEAR(form_factor(strip, h, 0.0, 0.0), std::sin(phi), 1e-9);
  // Off-centre: F = (sin φ2 − sin φ1) / 2 with φ the signed angles to the two edges.
  const double y = 250.0;
  const double p1 = std::atan((-w / 2 - y) / h), p2 = std::atan((w / 2 - y) / h);
  EXPECT_NEAR(form_factor(strip, h, 0.0, y), (std::sin(p2) - std::sin(p1)) / 2, 1e-9);
}

TEST(FormFactor, ASmallEmitterIsAPointSource) {
  const CabinetEmitter tiny{"A", 500, 300, 0.5, 0.5, 1};
  const double h = 600.0, x = 200.0, y = 100.0;
  const double r2 = (500 - x) * (500 - x) + (300 - y) * (300 - y) + h * h;
  EXPECT_NEAR(form_factor(tiny, h, x, y) / (0.25 * h * h / (std::numbers::pi * r2 * r2)), 1.0, 1e-6);
}

TEST(FormFactor, TwoHalvesAddUpToTheWholeAndNothingShinesAboveTheCeiling) {
  const CabinetEmitter whole{"TL84", 600, 300, 1000, 80, 1}, left{"TL84", 350, 300, 500, 80, 1},
      right{"TL84", 850, 300, 500, 80, 1};
  for (double x : {0.0, 333.0, 600.0, 1200.0})
    EXPECT_NEAR(form_factor(whole, 600, x, 50), form_factor(left, 600, x, 50) + form_factor(right, 600, x, 50), 1e-12);
  // The whole hemisphere (a huge ceiling) is F = 1.
  const CabinetEmitter sky{"D65", 0, 0, 1e9, 1e9, 1};
  EXPECT_NEAR(form_factor(sky, 600, 0, 0), 1.0, 1e-6);
}

}  // namespace
}  // namespace colorlab::verify
