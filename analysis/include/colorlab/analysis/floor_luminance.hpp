#pragma once
// The camera as an imaging luminance meter (issue 11): the cabinet floor mapped into a photograph, a spot's robust
// signal, and the flat field that turns signals into cd/m², fitted on a few spots the LS-110 read.
//
// Why a fit and not one gain: a lens passes less light away from its axis — vignetting, and the cos⁴ law of a wide
// view — so the same floor luminance gives tens of percent less signal at the frame's edge than at its centre.
// Both are radially symmetric about the optical axis and smooth, so the calibration models
//     L = S · (c0 + c1·ρ² + c2·ρ⁴ + …),  ρ = distance from the frame centre / half the frame's diagonal,
// with one gain (degree 0) for a lens known to be flat, and more terms as more spots are read. The fit minimises
// the relative residuals at the calibration spots (each reading counts the same, whatever its level).
#include <array>
#include <span>
#include <vector>

namespace colorlab::analysis {

// The floor rectangle (0..width_mm × 0..depth_mm, x from the left wall, y from the front edge) in an image, from the
// image positions of its corners: front-left, front-right, back-right, back-left (pixel centres at integers). A
// plane homography: exact for a lens without distortion. Throws Error(bad_parameter) for corners that are not a
// convex quadrilateral in that order.
class FloorMap {
 public:
  FloorMap(const std::array<std::array<double, 2>, 4>& corners_px, double width_mm, double depth_mm);
  std::array<double, 2> pixel_of(double x_mm, double y_mm) const;
  std::array<double, 2> floor_of(double x_px, double y_px) const;

 private:
  std::array<double, 9> h_{}, inv_{};
};

// The robust value of a spot's samples (§6.1.2's idea, scaled to a smooth field): the mean of the samples within
// ±max(4 robust σ, 2 % of the median) of the median, so hot and dead pixels and a dust shadow's 15-45 % drop are left
// out while the noise of every good pixel is kept. Throws Error(bad_data) for no samples.
struct SpotValue {
  double value = 0, median = 0, stdev = 0;  // stdev of the samples used
  std::size_t used = 0, total = 0;
};
SpotValue robust_spot_value(std::span<const double> samples);

struct FlatFieldSample {
  double x_px = 0, y_px = 0;  // pixel centres at integers
  double signal = 0;          // the camera's (e.g. green counts above black)
  double luminance = 0;       // the meter's reading there, cd/m²
};

struct FlatFieldFit {
  int degree = 0;                    // terms − 1; lowered to (spots − 1) when fewer spots were given
  std::vector<double> coefficients;  // c0, c1, …
  double centre_x = 0, centre_y = 0, radius = 1;
  std::vector<double> residual_pct;  // per calibration spot: 100 · (fitted − read) / read
  double luminance(double x_px, double y_px, double signal) const;
  double gain(double x_px, double y_px) const;  // cd/m² per unit of signal there
};

// Fits the flat field of an image (width × height: its centre and half-diagonal define ρ). Error(bad_parameter)
// when no spot is given, a signal or luminance is not positive, or degree < 0.
FlatFieldFit fit_flat_field(std::span<const FlatFieldSample> calibration, int width, int height, int degree);

}  // namespace colorlab::analysis
