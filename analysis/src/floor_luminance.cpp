#include "colorlab/analysis/floor_luminance.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <string>

#include "colorlab/core/error.hpp"

namespace colorlab::analysis {

namespace {

std::array<double, 9> to_array(const Eigen::Matrix3d& m) {
  std::array<double, 9> a{};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) a[static_cast<std::size_t>(r * 3 + c)] = m(r, c);
  return a;
}

std::array<double, 2> apply(const std::array<double, 9>& h, double x, double y) {
  const double w = h[6] * x + h[7] * y + h[8];
  return {(h[0] * x + h[1] * y + h[2]) / w, (h[3] * x + h[4] * y + h[5]) / w};
}

double cross(const std::array<double, 2>& o, const std::array<double, 2>& a, const std::array<double, 2>& b) {
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

}  // namespace

FloorMap::FloorMap(const std::array<std::array<double, 2>, 4>& c, double width_mm, double depth_mm) {
  if (!(width_mm > 0) || !(depth_mm > 0)) throw Error(ErrorClass::bad_parameter, "the floor's width and depth must be > 0 mm");
  // Convex and in one turning direction: corners given out of order would fold the floor over itself.
  double sign = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    const double z = cross(c[i], c[(i + 1) % 4], c[(i + 2) % 4]);
    if (!std::isfinite(z) || z == 0 || (sign != 0 && (z > 0) != (sign > 0))) {
      throw Error(ErrorClass::bad_parameter,
                  "the floor's corners must be a convex quadrilateral: front-left, front-right, back-right, back-left");
    }
    sign = z;
  }
  // Direct linear transform of the four correspondences, h33 = 1.
  const double floor[4][2] = {{0, 0}, {width_mm, 0}, {width_mm, depth_mm}, {0, depth_mm}};
  Eigen::Matrix<double, 8, 8> a;
  Eigen::Matrix<double, 8, 1> b;
  for (int i = 0; i < 4; ++i) {
    const double X = floor[i][0], Y = floor[i][1], u = c[static_cast<std::size_t>(i)][0], v = c[static_cast<std::size_t>(i)][1];
    a.row(2 * i) << X, Y, 1, 0, 0, 0, -u * X, -u * Y;
    a.row(2 * i + 1) << 0, 0, 0, X, Y, 1, -v * X, -v * Y;
    b(2 * i) = u;
    b(2 * i + 1) = v;
  }
  const Eigen::Matrix<double, 8, 1> x = a.fullPivLu().solve(b);
  Eigen::Matrix3d h;
  h << x(0), x(1), x(2), x(3), x(4), x(5), x(6), x(7), 1.0;
  h_ = to_array(h);
  inv_ = to_array(h.inverse());
}

std::array<double, 2> FloorMap::pixel_of(double x_mm, double y_mm) const { return apply(h_, x_mm, y_mm); }
std::array<double, 2> FloorMap::floor_of(double x_px, double y_px) const { return apply(inv_, x_px, y_px); }

SpotValue robust_spot_value(std::span<const double> samples) {
  if (samples.empty()) throw Error(ErrorClass::bad_data, "a floor spot has no pixels in the image");
  std::vector<double> s(samples.begin(), samples.end());
  auto median_of = [](std::vector<double>& v) {
    const std::size_t m = v.size() / 2;
    std::nth_element(v.begin(), v.begin() + static_cast<long>(m), v.end());
    double med = v[m];
    if (v.size() % 2 == 0) med = (med + *std::max_element(v.begin(), v.begin() + static_cast<long>(m))) / 2;
    return med;
  };
  SpotValue out;
  out.total = s.size();
  out.median = median_of(s);
  std::vector<double> dev(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) dev[i] = std::abs(s[i] - out.median);
  const double sigma = 1.4826 * median_of(dev);  // the MAD's σ of a normal distribution
  const double band = std::max(4 * sigma, 0.02 * std::abs(out.median));
  double sum = 0, sum_sq = 0;
  for (double v : samples) {
    if (std::abs(v - out.median) > band) continue;
    sum += v;
    sum_sq += v * v;
    ++out.used;
  }
  out.value = sum / static_cast<double>(out.used);  // the median itself is always within the band
  out.stdev = out.used > 1 ? std::sqrt(std::max(0.0, (sum_sq - sum * out.value) / static_cast<double>(out.used - 1))) : 0.0;
  return out;
}

double FlatFieldFit::gain(double x_px, double y_px) const {
  const double dx = x_px - centre_x, dy = y_px - centre_y;
  const double rho2 = (dx * dx + dy * dy) / (radius * radius);
  double g = 0, p = 1;
  for (double c : coefficients) {
    g += c * p;
    p *= rho2;
  }
  return g;
}

double FlatFieldFit::luminance(double x_px, double y_px, double signal) const { return signal * gain(x_px, y_px); }

FlatFieldFit fit_flat_field(std::span<const FlatFieldSample> cal, int width, int height, int degree) {
  if (cal.empty()) throw Error(ErrorClass::bad_parameter, "a flat-field fit needs at least one calibration spot");
  if (degree < 0) throw Error(ErrorClass::bad_parameter, "the flat field's degree must be ≥ 0");
  if (width <= 0 || height <= 0) throw Error(ErrorClass::bad_parameter, "the image has no size");
  FlatFieldFit fit;
  // Pixel centres at integers: the frame's centre is at (w − 1)/2.
  fit.centre_x = (width - 1) / 2.0;
  fit.centre_y = (height - 1) / 2.0;
  fit.radius = std::hypot(width / 2.0, height / 2.0);
  fit.degree = std::min<int>(degree, static_cast<int>(cal.size()) - 1);
  const int terms = fit.degree + 1;
  Eigen::MatrixXd a(static_cast<Eigen::Index>(cal.size()), terms);
  Eigen::VectorXd b = Eigen::VectorXd::Ones(static_cast<Eigen::Index>(cal.size()));
  for (std::size_t i = 0; i < cal.size(); ++i) {
    const auto& s = cal[i];
    if (!(s.signal > 0) || !(s.luminance > 0)) {
      throw Error(ErrorClass::bad_parameter, "calibration spot " + std::to_string(i + 1) + ": the signal (" +
                                                 std::to_string(s.signal) + ") and the luminance (" +
                                                 std::to_string(s.luminance) + ") must be > 0");
    }
    const double dx = s.x_px - fit.centre_x, dy = s.y_px - fit.centre_y;
    const double rho2 = (dx * dx + dy * dy) / (fit.radius * fit.radius);
    double p = 1;
    // Row i: S·ρ^(2k) / L, so that a·c = 1 is "fitted = read" in relative terms.
    for (int k = 0; k < terms; ++k, p *= rho2) a(static_cast<Eigen::Index>(i), k) = s.signal * p / s.luminance;
  }
  const Eigen::VectorXd c = a.colPivHouseholderQr().solve(b);
  fit.coefficients.assign(c.data(), c.data() + c.size());
  for (const auto& s : cal) fit.residual_pct.push_back(100.0 * (fit.luminance(s.x_px, s.y_px, s.signal) - s.luminance) / s.luminance);
  return fit;
}

}  // namespace colorlab::analysis
