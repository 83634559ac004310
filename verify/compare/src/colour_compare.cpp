// Colour, §7.3 (photograph -> XYZ through the characterization, ΔE00) and §7.4 (spectral rendering -> raw counts
// through the black box). Uncertainties are propagated by perturbing the measured input along each source and
// mapping the change through the same functions the comparison uses, so no derivative is written twice.
#include <algorithm>
#include <cmath>

#include "colorlab/analysis/color_difference.hpp"
#include "colorlab/core/error.hpp"
#include "comparisons.hpp"
#include "rendering_noise.hpp"
#include "rendering_sample.hpp"

namespace colorlab::verify::detail {
namespace {

Eigen::Vector3d lab_vec(const analysis::Lab& l) { return {l.L, l.a, l.b}; }
analysis::Lab to_lab(const Eigen::Vector3d& v) { return {v[0], v[1], v[2]}; }
analysis::Xyz scaled(const analysis::Xyz& x, double f) { return {x.X * f, x.Y * f, x.Z * f}; }

// ΔE00 is locally a quadratic form in ΔL*, Δa*, Δb*: its matrix at `at`, from ΔE00² along the axes and their sums.
// Its Cholesky factor maps a Lab difference into coordinates where ΔE00 is the Euclidean length, so covariances
// and the characterization's ΔE00 errors can be added there.
Eigen::Matrix3d de00_metric_factor(const analysis::Lab& at) {
  constexpr double h = 0.25;
  const Eigen::Vector3d p = lab_vec(at);
  auto q = [&](const Eigen::Vector3d& d) {
    const double a = analysis::delta_e2000(at, to_lab(p + d)), b = analysis::delta_e2000(at, to_lab(p - d));
    return 0.5 * (a * a + b * b);
  };
  Eigen::Matrix3d g;
  const Eigen::Matrix3d e = Eigen::Matrix3d::Identity() * h;
  for (int i = 0; i < 3; ++i) g(i, i) = q(e.col(i)) / (h * h);
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j)
      g(i, j) = g(j, i) = (q(e.col(i) + e.col(j)) - q(e.col(i)) - q(e.col(j))) / (2 * h * h);
  Eigen::LLT<Eigen::Matrix3d> llt(g + 1e-9 * Eigen::Matrix3d::Identity());
  if (llt.info() != Eigen::Success) return Eigen::Matrix3d::Identity();
  return llt.matrixL().transpose();
}

// The mean outer product of the held-out errors of the `k` training patches nearest to `at`: the mapping's error
// covariance in that region (of colour space, or of the camera's counts).
Eigen::Matrix3d regional_covariance(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3d>& errors,
                                    const Eigen::Vector3d& at, int k) {
  std::vector<std::pair<double, std::size_t>> d;
  d.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) d.emplace_back((points[i] - at).squaredNorm(), i);
  const auto n = std::min<std::size_t>(static_cast<std::size_t>(std::max(1, k)), d.size());
  std::partial_sort(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(n), d.end());
  Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < n; ++i) c += errors[d[i].second] * errors[d[i].second].transpose();
  return c / static_cast<double>(n);
}

// The held-out errors contain the training photograph's frame noise, which the photograph under comparison has
// again and the budget counts as "frame noise": the mapping's own part is what exceeds it (eigenvalues clamped
// at zero so the difference stays a covariance).
Eigen::Matrix3d beyond(const Eigen::Matrix3d& held_out, const Eigen::Matrix3d& frame_noise) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(held_out - frame_noise);
  return es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).asDiagonal() * es.eigenvectors().transpose();
}

std::vector<PixelRect> regions_of(const std::vector<PatchMeasurement>& patches) {
  std::vector<PixelRect> out;
  out.reserve(patches.size());
  for (const auto& p : patches) out.push_back(p.rendering_region);
  return out;
}

}  // namespace

double median_ratio(std::vector<double> r, const char* what) {
  r.erase(std::remove_if(r.begin(), r.end(), [](double x) { return !std::isfinite(x) || x <= 0; }), r.end());
  if (r.empty())
    throw Error(ErrorClass::bad_data, std::string("no positive values to fit the scale of the ") + what + " on",
                "give the renderer's units (--scale) or a rendering that is not black where the measurement looked");
  const auto mid = r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2);
  std::nth_element(r.begin(), mid, r.end());
  if (r.size() % 2) return *mid;
  return 0.5 * (*mid + *std::max_element(r.begin(), mid));
}

void conclude(Comparison& c, const Eigen::VectorXd& delta, const Budget& budget, const CompareOptions& o,
              double reported, double unit, double cannot_tell_limit) {
  const auto dim = static_cast<int>(delta.size());
  const Eigen::MatrixXd total = budget.total(dim);
  const Judgement j = judge(delta, total, o.k);
  c.difference = reported;
  c.mahalanobis = j.mahalanobis;
  c.threshold = j.threshold;
  c.verdict = j.differs ? Verdict::differs : Verdict::agrees;
  c.expanded = j.mahalanobis > 0 ? std::abs(reported) * j.threshold / j.mahalanobis : j.expanded_along * unit;
  Eigen::VectorXd dir = delta;
  if (dir.norm() == 0) dir = Eigen::VectorXd::Unit(dim, 0);
  dir.normalize();
  for (auto& [name, u] : budget.along(dir)) c.budget.emplace_back(name, u * unit);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(total);
  c.cannot_tell = j.threshold * std::sqrt(es.eigenvalues().maxCoeff()) * unit > cannot_tell_limit;
}

void compare_colour_73(const Rendering& r, const MeasuredScene& s, const CompareOptions& o, Verification& v) {
  const auto& ch = *s.characterization;
  if (!ch.to_xyz) throw Error(ErrorClass::bad_parameter, "the characterization has no mapping to XYZ");
  if (ch.cv_lab.size() != ch.cv_error.size() || ch.cv_lab.empty())
    throw Error(ErrorClass::bad_data, "the characterization's cross-validated errors are missing or do not match their patches",
                "the characterize-camera run must store each training patch's held-out error");
  const ToXyz tx(r);
  std::vector<analysis::Xyz> rendered;
  rendered.reserve(s.patches.size());
  for (const auto& p : s.patches) rendered.push_back(tx(region_mean(r, p.rendering_region)));

  // The rendering's XYZ into the measurement's relative scale (the lamp's perfect diffuser at Y = 100).
  ScaleUsed sc{"colour_7_3", "given", 1};
  // A given scale needs the white's metered luminance at the chart; runs that did not meter it (characterize-camera
  // does not) get §7.3's factor fitted, and `scales` says so, while the light comparisons keep the given one.
  if (o.scale && s.white_luminance_cd_m2 && *s.white_luminance_cd_m2 > 0) {
    sc.factor = *o.scale * 100.0 / *s.white_luminance_cd_m2;
  } else {
    std::vector<double> ratios;
    for (std::size_t i = 0; i < s.patches.size(); ++i) ratios.push_back(ch.to_xyz(s.patches[i].camera).Y / rendered[i].Y);
    sc.factor = median_ratio(ratios, "§7.3 patches");
    sc.how = "fitted";
  }
  v.scales.push_back(sc);

  std::vector<Eigen::Vector3d> cv_points, cv_errors;
  for (std::size_t i = 0; i < ch.cv_lab.size(); ++i) {
    cv_points.emplace_back(lab_vec(ch.cv_lab[i]));
    cv_errors.emplace_back(ch.cv_error[i][0], ch.cv_error[i][1], ch.cv_error[i][2]);
  }
  const double drift_sd = s.lamp_drift_bound / std::sqrt(3.0);  // a bound read as a rectangular distribution
  const double a = s.locator_accuracy_px;
  const RenderingNoise noise = o.rendering_noise ? rendering_noise(r, regions_of(s.patches), tx.matrix(), o.noise_neighbours)
                                                 : RenderingNoise{};

  for (std::size_t i = 0; i < s.patches.size(); ++i) {
    const auto& p = s.patches[i];
    auto meas_lab = [&](const Rgb3& cam) { return lab_vec(analysis::xyz_to_lab(ch.to_xyz(cam), ch.white)); };
    auto rend_lab = [&](const analysis::Xyz& x, double f) { return lab_vec(analysis::xyz_to_lab(scaled(x, f), ch.white)); };
    const Eigen::Vector3d lm = meas_lab(p.camera);
    const Eigen::Vector3d lr = rend_lab(rendered[i], sc.factor);
    const Eigen::Matrix3d z = de00_metric_factor(to_lab(lm));

    Budget b;
    Eigen::Matrix3d frame = Eigen::Matrix3d::Zero();
    for (int c = 0; c < 3; ++c) {
      Rgb3 cam = p.camera;
      cam[static_cast<std::size_t>(c)] += p.frame_noise[static_cast<std::size_t>(c)];
      const Eigen::Vector3d d = z * (meas_lab(cam) - lm);
      frame += d * d.transpose();
    }
    b.add("characterization", beyond(z * regional_covariance(cv_points, cv_errors, lm, o.cv_neighbours) * z.transpose(), frame));
    b.add("frame noise", frame);
    if (sc.how == "given") {
      // A fitted factor takes up any common change of the lamp's level; a given one does not.
      if (drift_sd > 0) {
        Rgb3 cam = p.camera;
        for (auto& x : cam) x *= 1 + drift_sd;
        b.add_vector("lamp drift", z * (meas_lab(cam) - lm));
      }
      if (s.white_relative_sd > 0)
        b.add_vector("ls110 repeatability", z * (rend_lab(rendered[i], sc.factor * (1 + s.white_relative_sd)) - lr));
    }
    if (!noise.covariance.empty()) {
      // The rendered XYZ's covariance carried to the ΔE00 coordinates through the Jacobian of its L*a*b*.
      Eigen::Matrix3d jac;
      const Eigen::Vector3d x0(rendered[i].X, rendered[i].Y, rendered[i].Z);
      for (int c = 0; c < 3; ++c) {
        const double h = 1e-4 * std::max(x0.norm(), 1e-12);
        Eigen::Vector3d up = x0, down = x0;
        up[c] += h, down[c] -= h;
        jac.col(c) = (rend_lab({up[0], up[1], up[2]}, sc.factor) - rend_lab({down[0], down[1], down[2]}, sc.factor)) / (2 * h);
      }
      b.add("rendering noise", z * jac * noise.covariance[i] * jac.transpose() * z.transpose());
    }
    if (a > 0)
      for (auto [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}}) {
        const auto plus = tx(shifted_mean(r, p.rendering_region, dx, dy));
        const auto minus = tx(shifted_mean(r, p.rendering_region, -dx, -dy));
        const analysis::Xyz moved{rendered[i].X + 0.5 * a * (plus.X - minus.X), rendered[i].Y + 0.5 * a * (plus.Y - minus.Y),
                                  rendered[i].Z + 0.5 * a * (plus.Z - minus.Z)};
        b.add_vector("misregistration", z * (rend_lab(moved, sc.factor) - lr));
      }

    Comparison c;
    c.kind = "colour_7_3";
    c.where = p.id;
    c.rendered = {lr[0], lr[1], lr[2]};
    c.measured = {lm[0], lm[1], lm[2]};
    c.noise_left_out = noise.own_level(i);
    const double de = analysis::delta_e2000(to_lab(lm), to_lab(lr));
    conclude(c, z * (lr - lm), b, o, de, 1.0, o.cannot_tell_de00);
    v.comparisons.push_back(std::move(c));
  }
}

void compare_colour_74(const Rendering& r, const MeasuredScene& s, const CompareOptions& o, Verification& v) {
  const auto& bb = *s.black_box;
  const auto& wl = r.wavelengths_nm;
  for (const auto& curve : bb.sensitivity)
    if (curve.size() != bb.wavelengths_nm.size() || curve.empty())
      throw Error(ErrorClass::bad_data, "the black box's sensitivities do not match their wavelengths");
  // Sensitivities at the rendering's band centres (linear; zero outside the fitted range), times band width.
  const auto w = band_widths(wl);
  Eigen::Matrix3Xd m(3, static_cast<Eigen::Index>(wl.size()));
  const auto& g = bb.wavelengths_nm;
  for (std::size_t i = 0; i < wl.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const auto& sc = bb.sensitivity[static_cast<std::size_t>(c)];
      double val = 0;
      if (wl[i] >= g.front() && wl[i] <= g.back()) {
        const auto it = std::upper_bound(g.begin(), g.end(), wl[i]);
        const std::size_t hi = std::min<std::size_t>(static_cast<std::size_t>(it - g.begin()), g.size() - 1);
        const std::size_t lo = hi == 0 ? 0 : hi - 1;
        const double t = g[hi] == g[lo] ? 0 : (wl[i] - g[lo]) / (g[hi] - g[lo]);
        val = (1 - t) * sc[lo] + t * sc[hi];
      }
      m(c, static_cast<Eigen::Index>(i)) = val * w[i];
    }

  std::vector<Eigen::Vector3d> predicted;
  std::vector<double> ratios;
  for (const auto& p : s.patches) {
    predicted.emplace_back(m * region_mean(r, p.rendering_region));
    for (int c = 0; c < 3; ++c) ratios.push_back(p.camera[static_cast<std::size_t>(c)] / predicted.back()[c]);
  }
  // The black box knows the camera's spectral shape, not its absolute responsivity: one factor is always fitted
  // here, so this comparison sees colour (spectral) errors, and the light comparison the level.
  const ScaleUsed sc{"colour_7_4", "fitted", median_ratio(ratios, "§7.4 raw patches")};
  v.scales.push_back(sc);

  std::vector<Eigen::Vector3d> cv_points, cv_res;
  double full = 0;
  for (const auto& c : bb.cv_camera) full = std::max({full, c[0], c[1], c[2]});
  if (full <= 0) full = 1;
  for (std::size_t i = 0; i < bb.cv_camera.size(); ++i)
    cv_points.emplace_back(Eigen::Vector3d(bb.cv_camera[i][0], bb.cv_camera[i][1], bb.cv_camera[i][2]) / full);
  for (const auto& r : bb.cv_residual) cv_res.emplace_back(r[0], r[1], r[2]);
  if (bb.cv_residual.size() != cv_points.size() || cv_points.empty())
    throw Error(ErrorClass::bad_data, "the black box's cross-validated residuals are missing or do not match their patches");

  const double a = s.locator_accuracy_px;
  const RenderingNoise noise = o.rendering_noise ? rendering_noise(r, regions_of(s.patches), m, o.noise_neighbours) : RenderingNoise{};
  for (std::size_t i = 0; i < s.patches.size(); ++i) {
    const auto& p = s.patches[i];
    const Eigen::Vector3d meas(p.camera[0], p.camera[1], p.camera[2]);
    const Eigen::Vector3d pred = predicted[i] * sc.factor;
    Budget b;
    const Eigen::Matrix3d frame = Eigen::Vector3d(p.frame_noise[0] * p.frame_noise[0], p.frame_noise[1] * p.frame_noise[1],
                                                  p.frame_noise[2] * p.frame_noise[2])
                                      .asDiagonal();
    b.add("black box", beyond(regional_covariance(cv_points, cv_res, meas / full, o.cv_neighbours), frame));
    b.add("frame noise", frame);
    if (!noise.covariance.empty()) b.add("rendering noise", sc.factor * sc.factor * noise.covariance[i]);
    if (a > 0)
      for (auto [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}}) {
        const Eigen::Vector3d d = m * (shifted_mean(r, p.rendering_region, dx, dy) - shifted_mean(r, p.rendering_region, -dx, -dy));
        b.add_vector("misregistration", 0.5 * a * sc.factor * d);
      }
    Comparison c;
    c.kind = "colour_7_4";
    c.where = p.id;
    c.rendered = {pred[0], pred[1], pred[2]};
    c.measured = {meas[0], meas[1], meas[2]};
    c.noise_left_out = noise.own_level(i);
    const double unit = 1.0 / std::max(meas.norm(), 1e-12);
    conclude(c, pred - meas, b, o, (pred - meas).norm() * unit, unit, o.cannot_tell_relative);
    v.comparisons.push_back(std::move(c));
  }
}

}  // namespace colorlab::verify::detail
