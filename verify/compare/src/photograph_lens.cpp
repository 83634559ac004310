#include "colorlab/verify/compare/photograph_lens.hpp"

#include <cmath>

#include "colorlab/core/error.hpp"

namespace colorlab::verify {

namespace {

void check(const PhotographLens& l) {
  if (!(l.fx > 0 && l.fy > 0) || !std::isfinite(l.cx) || !std::isfinite(l.cy) || !std::isfinite(l.k1) || !std::isfinite(l.k2))
    throw Error(ErrorClass::bad_parameter, "the photograph's lens has no positive focal lengths or a non-finite parameter",
                "give fx, fy, cx, cy[, k1, k2] in the photograph's pixels (colorlab lens list shows the lab's)");
}

}  // namespace

std::array<double, 2> distort_px(const PhotographLens& l, const std::array<double, 2>& p) {
  check(l);
  const double x = (p[0] - l.cx) / l.fx, y = (p[1] - l.cy) / l.fy, r2 = x * x + y * y;
  const double k = 1 + l.k1 * r2 + l.k2 * r2 * r2;
  return {l.cx + l.fx * x * k, l.cy + l.fy * y * k};
}

std::array<double, 2> undistort_px(const PhotographLens& l, const std::array<double, 2>& p) {
  check(l);
  const double xd = (p[0] - l.cx) / l.fx, yd = (p[1] - l.cy) / l.fy, rd = std::hypot(xd, yd);
  if (rd == 0 || (l.k1 == 0 && l.k2 == 0)) return p;
  // The model is radial: solve r (1 + k1 r² + k2 r⁴) = rd for the undistorted radius r, then scale the point. The
  // function rises from 0 while its derivative is positive; a root past that fold is not the lens's.
  double r = rd;
  for (int i = 0; i < 50; ++i) {
    const double r2 = r * r, f = r * (1 + l.k1 * r2 + l.k2 * r2 * r2) - rd, d = 1 + 3 * l.k1 * r2 + 5 * l.k2 * r2 * r2;
    if (!(d > 0)) break;
    const double step = f / d;
    r -= step;
    if (std::abs(step) < 1e-15 * (1 + r)) {
      const double r2e = r * r;
      if (r > 0 && 1 + 3 * l.k1 * r2e + 5 * l.k2 * r2e * r2e > 0) return {l.cx + l.fx * xd * r / rd, l.cy + l.fy * yd * r / rd};
      break;
    }
  }
  throw Error(ErrorClass::bad_data,
              "pixel (" + std::to_string(p[0]) + ", " + std::to_string(p[1]) + ") lies beyond where the lens model (k1 " +
                  std::to_string(l.k1) + ", k2 " + std::to_string(l.k2) + ") is one-to-one",
              "check the lens calibration is the photograph's (its size and its k1, k2)");
}

}  // namespace colorlab::verify
