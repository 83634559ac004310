#include "colorlab/analysis/colorimetry.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "parse_util.hpp"

namespace colorlab::analysis {

namespace {
Eigen::RowVectorXd trapezoid_weights(const std::vector<double>& g) {
  Eigen::RowVectorXd w = Eigen::RowVectorXd::Zero(static_cast<Eigen::Index>(g.size()));
  for (std::size_t i = 0; i + 1 < g.size(); ++i) {
    double h = g[i + 1] - g[i];
    w(static_cast<Eigen::Index>(i)) += h / 2;
    w(static_cast<Eigen::Index>(i + 1)) += h / 2;
  }
  return w;
}
}  // namespace

ReflectanceIntegrator::ReflectanceIntegrator(const SpectralSet& illuminant, const SpectralSet& observer,
                                             const std::vector<double>& reflectance_grid, IntegrationOptions opt) {
  illuminant.check_shape();
  observer.check_shape();
  if (illuminant.size() != 1) detail::fail(illuminant.source + ": expected exactly one illuminant spectrum");
  if (observer.size() != 3) detail::fail(observer.source + ": expected three colour matching functions");
  validate_emission(illuminant);
  *this = IntegratorGrids(illuminant.wavelengths, observer, reflectance_grid, opt).integrator(illuminant);
}

IntegratorGrids::IntegratorGrids(const std::vector<double>& illuminant_grid, const SpectralSet& observer,
                                 const std::vector<double>& reflectance_grid, IntegrationOptions opt)
    : illuminant_grid_(illuminant_grid), reflectance_grid_(reflectance_grid), step_nm_(opt.step_nm) {
  observer.check_shape();
  if (observer.size() != 3) detail::fail(observer.source + ": expected three colour matching functions");
  if (reflectance_grid.size() < 2) detail::fail("reflectance grid needs at least 2 wavelengths");
  double lo = observer.wavelengths.front(), hi = observer.wavelengths.back();
  if (!opt.extrapolate_illuminant) {
    lo = std::max(lo, illuminant_grid.front());
    hi = std::min(hi, illuminant_grid.back());
  }
  if (!opt.extrapolate_reflectance) {
    lo = std::max(lo, reflectance_grid.front());
    hi = std::min(hi, reflectance_grid.back());
  }
  if (!(hi > lo)) {
    std::ostringstream os;
    os << "illuminant, observer and reflectance grids do not overlap (common range " << lo << "-" << hi << " nm)";
    detail::fail(os.str());
  }
  std::vector<double> fine = uniform_grid(lo, hi, opt.step_nm);
  if (fine.back() < hi - 1e-9) fine.push_back(hi);
  std::vector<double> lamp_points = fine;
  for (double& w : lamp_points) w = std::clamp(w, illuminant_grid.front(), illuminant_grid.back());
  illuminant_ = resampling_matrix(illuminant_grid, lamp_points, opt.illuminant);
  cmf_ = observer.values * resampling_matrix(observer.wavelengths, fine, opt.observer).transpose();
  std::vector<double> clamped = fine;
  for (double& w : clamped) w = std::clamp(w, reflectance_grid.front(), reflectance_grid.back());
  // Sprague where the grid allows it, the natural spline on short or irregular grids.
  const Interpolation refl_method = opt.reflectance == Interpolation::sprague && !sprague_applicable(reflectance_grid)
                                        ? Interpolation::cubic_spline
                                        : opt.reflectance;
  reflectance_ = resampling_matrix(reflectance_grid, clamped, refl_method);
}

ReflectanceIntegrator IntegratorGrids::integrator(const SpectralSet& illuminant) const {
  illuminant.check_shape();
  if (illuminant.size() != 1) detail::fail(illuminant.source + ": expected exactly one illuminant spectrum");
  if (illuminant.wavelengths != illuminant_grid_) detail::fail(illuminant.source + ": not on the illuminant grid these weights were built for");
  validate_emission(illuminant);
  const Eigen::RowVectorXd S = illuminant.values * illuminant_.transpose();
  // CIE 15 sums S·x̄·R·Δλ over the grid (rectangle rule); the normalisation k cancels Δλ anyway.
  const Eigen::RowVectorXd w = Eigen::RowVectorXd::Constant(cmf_.cols(), step_nm_).cwiseProduct(S);
  Eigen::MatrixXd lamp_cmf = cmf_.array().rowwise() * w.array();  // 3 × fine
  const double k = 100.0 / lamp_cmf.row(1).sum();
  lamp_cmf *= k;
  ReflectanceIntegrator out;
  out.grid_ = reflectance_grid_;
  out.weights_ = lamp_cmf * reflectance_;
  out.white_ = {lamp_cmf.row(0).sum(), 100.0, lamp_cmf.row(2).sum()};
  return out;
}

Xyz ReflectanceIntegrator::xyz(const Eigen::Ref<const Eigen::RowVectorXd>& r) const {
  if (r.size() != weights_.cols())
    detail::fail("reflectance has " + std::to_string(r.size()) + " samples, integrator expects " +
                 std::to_string(weights_.cols()));
  Eigen::Vector3d v = weights_ * r.transpose();
  return {v(0), v(1), v(2)};
}

std::vector<Xyz> ReflectanceIntegrator::xyz(const SpectralSet& set) const {
  validate_reflectance(set);
  if (set.wavelengths.size() != grid_.size() || !std::equal(grid_.begin(), grid_.end(), set.wavelengths.begin(),
                                                            [](double a, double b) { return std::abs(a - b) < 1e-6; }))
    detail::fail(set.source + ": wavelength grid differs from the one this integrator was built for");
  std::vector<Xyz> out;
  out.reserve(set.size());
  Eigen::MatrixXd all = weights_ * set.values.transpose();
  for (Eigen::Index i = 0; i < all.cols(); ++i) out.push_back({all(0, i), all(1, i), all(2, i)});
  return out;
}

std::vector<Xyz> reflectance_to_xyz(const SpectralSet& refl, const SpectralSet& illuminant, Observer observer,
                                    IntegrationOptions options) {
  refl.check_shape();
  ReflectanceIntegrator integ(illuminant, load_observer(observer), refl.wavelengths, options);
  return integ.xyz(refl);
}

std::vector<Xyz> emission_to_xyz(const SpectralSet& spectra, Observer observer, double k) {
  validate_emission(spectra);
  const SpectralSet obs = load_observer(observer);
  const double lo = std::max(spectra.wavelengths.front(), obs.wavelengths.front());
  const double hi = std::min(spectra.wavelengths.back(), obs.wavelengths.back());
  std::vector<double> grid;
  for (double w : spectra.wavelengths)
    if (w >= lo - 1e-9 && w <= hi + 1e-9) grid.push_back(w);
  if (grid.size() < 2) detail::fail(spectra.source + ": spectrum does not overlap the observer's 360-830 nm");
  const Eigen::MatrixXd cmf = obs.values * resampling_matrix(obs.wavelengths, grid, Interpolation::cubic_spline).transpose();
  const Eigen::RowVectorXd w = trapezoid_weights(grid);
  const Eigen::MatrixXd sub = spectra.values * resampling_matrix(spectra.wavelengths, grid, Interpolation::linear).transpose();
  std::vector<Xyz> out;
  for (Eigen::Index i = 0; i < sub.rows(); ++i) {
    Eigen::RowVectorXd e = sub.row(i).cwiseProduct(w);
    Eigen::Vector3d v = cmf * e.transpose();
    double scale = k > 0 ? k : (v(1) > 0 ? 100.0 / v(1) : 0.0);
    out.push_back({v(0) * scale, v(1) * scale, v(2) * scale});
  }
  return out;
}

Xyz illuminant_white(const SpectralSet& illuminant, Observer observer) {
  return emission_to_xyz(illuminant, observer, 0.0).front();
}

XyY xyz_to_xyy(const Xyz& c) {
  double s = c.X + c.Y + c.Z;
  if (s <= 0) return {0, 0, 0};
  return {c.X / s, c.Y / s, c.Y};
}

Xyz xyy_to_xyz(const XyY& c) {
  if (c.y <= 0) return {0, 0, 0};
  return {c.x * c.Y / c.y, c.Y, (1 - c.x - c.y) * c.Y / c.y};
}

namespace {
constexpr double kDelta = 6.0 / 29.0;
double lab_f(double t) { return t > kDelta * kDelta * kDelta ? std::cbrt(t) : t / (3 * kDelta * kDelta) + 4.0 / 29.0; }
double lab_f_inv(double f) { return f > kDelta ? f * f * f : 3 * kDelta * kDelta * (f - 4.0 / 29.0); }
void check_white(const Xyz& w) {
  if (!(w.X > 0 && w.Y > 0 && w.Z > 0)) detail::fail("reference white must have positive X, Y, Z");
}
}  // namespace

Lab xyz_to_lab(const Xyz& c, const Xyz& w) {
  check_white(w);
  double fx = lab_f(c.X / w.X), fy = lab_f(c.Y / w.Y), fz = lab_f(c.Z / w.Z);
  return {116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)};
}

Xyz lab_to_xyz(const Lab& c, const Xyz& w) {
  check_white(w);
  double fy = (c.L + 16) / 116, fx = fy + c.a / 500, fz = fy - c.b / 200;
  return {w.X * lab_f_inv(fx), w.Y * lab_f_inv(fy), w.Z * lab_f_inv(fz)};
}

Luv xyz_to_luv(const Xyz& c, const Xyz& w) {
  check_white(w);
  double L = 116 * lab_f(c.Y / w.Y) - 16;
  double d = c.X + 15 * c.Y + 3 * c.Z, dw = w.X + 15 * w.Y + 3 * w.Z;
  double u = d > 0 ? 4 * c.X / d : 0, v = d > 0 ? 9 * c.Y / d : 0;
  double un = 4 * w.X / dw, vn = 9 * w.Y / dw;
  return {L, 13 * L * (u - un), 13 * L * (v - vn)};
}

Xyz bradford_adapt(const Xyz& c, const Xyz& from, const Xyz& to) {
  check_white(from);
  check_white(to);
  Eigen::Matrix3d M;
  M << 0.8951, 0.2664, -0.1614, -0.7502, 1.7135, 0.0367, 0.0389, -0.0685, 1.0296;
  Eigen::Vector3d s = M * Eigen::Vector3d(from.X, from.Y, from.Z);
  Eigen::Vector3d d = M * Eigen::Vector3d(to.X, to.Y, to.Z);
  Eigen::Matrix3d A = M.inverse() * (d.array() / s.array()).matrix().asDiagonal() * M;
  Eigen::Vector3d r = A * Eigen::Vector3d(c.X, c.Y, c.Z);
  return {r(0), r(1), r(2)};
}

}  // namespace colorlab::analysis
