#include "colorlab/analysis/sensitivity_prior.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <map>

#include "colorlab/analysis/blackbox.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::analysis {

namespace {

// "<camera>_R" → {"<camera>", 0}; "G" → {"", 1}; anything else → channel −1.
std::pair<std::string, int> split_channel(const std::string& name) {
  auto channel_of = [](char c) {
    switch (std::toupper(static_cast<unsigned char>(c))) {
      case 'R': return 0;
      case 'G': return 1;
      case 'B': return 2;
      default: return -1;
    }
  };
  if (name.size() == 1) return {"", channel_of(name[0])};
  if (name.size() > 2 && name[name.size() - 2] == '_') return {name.substr(0, name.size() - 2), channel_of(name.back())};
  return {name, -1};
}

}  // namespace

std::vector<std::string> camera_names(const SpectralSet& curves) {
  std::vector<std::string> out;
  for (const auto& n : curves.names) {
    auto [camera, channel] = split_channel(n);
    if (channel >= 0 && std::find(out.begin(), out.end(), camera) == out.end()) out.push_back(camera);
  }
  return out;
}

SensitivityPrior learn_sensitivity_prior(const SpectralSet& curves, const std::vector<double>& wavelengths,
                                         const std::vector<std::string>& exclude) {
  curves.check_shape();
  if (wavelengths.size() < 3) throw Error(ErrorClass::bad_parameter, "sensitivity prior: need at least 3 wavelengths");
  if (curves.wavelengths.empty() || wavelengths.front() < curves.wavelengths.front() - 1e-9 ||
      wavelengths.back() > curves.wavelengths.back() + 1e-9)
    throw Error(ErrorClass::bad_data, "sensitivity prior: curves in " + curves.source + " do not cover " +
                                          std::to_string(wavelengths.front()) + "–" + std::to_string(wavelengths.back()) +
                                          " nm of the spectra");
  std::map<std::string, std::array<int, 3>> rows;  // camera → sample row per channel
  for (std::size_t i = 0; i < curves.names.size(); ++i) {
    auto [camera, channel] = split_channel(curves.names[i]);
    if (channel < 0) continue;
    if (std::find(exclude.begin(), exclude.end(), camera) != exclude.end()) continue;
    auto it = rows.try_emplace(camera, std::array<int, 3>{-1, -1, -1}).first;
    it->second[static_cast<std::size_t>(channel)] = static_cast<int>(i);
  }
  SensitivityPrior prior;
  prior.wavelengths = wavelengths;
  std::vector<std::array<int, 3>> complete;
  for (const auto& [camera, r] : rows)
    if (r[0] >= 0 && r[1] >= 0 && r[2] >= 0) {
      complete.push_back(r);
      prior.cameras.push_back(camera.empty() ? "camera" : camera);
    }
  if (complete.size() < 3)
    throw Error(ErrorClass::bad_data, "sensitivity prior: " + curves.source + " has " + std::to_string(complete.size()) +
                                          " complete cameras (columns <camera>_R/_G/_B) after exclusions; need at least 3");
  const Eigen::MatrixXd resample_rows = resampling_matrix(curves.wavelengths, wavelengths, Interpolation::linear);
  const auto bands = static_cast<Eigen::Index>(wavelengths.size());
  const auto ncam = static_cast<Eigen::Index>(complete.size());
  for (std::size_t c = 0; c < 3; ++c) {
    Eigen::MatrixXd M(bands, ncam);
    for (Eigen::Index j = 0; j < ncam; ++j) {
      const auto row = static_cast<Eigen::Index>(complete[static_cast<std::size_t>(j)][c]);
      Eigen::VectorXd v = resample_rows * curves.values.row(row).transpose();
      const double peak = v.maxCoeff();
      if (!v.allFinite() || !(peak > 0) || (v.array() < -1e-6 * peak).any())
        throw Error(ErrorClass::bad_data, "sensitivity prior: curve '" + curves.names[static_cast<std::size_t>(row)] +
                                              "' in " + curves.source + " is not finite, non-negative and non-zero");
      M.col(j) = v / peak;  // shape only: the fit supplies the camera's gain
    }
    ChannelPrior& p = prior.channels[c];
    p.mean = M.rowwise().mean();
    // A new camera is not a combination of the training cameras: with 27 cameras and 33 bands the principal
    // directions span at most 26 dimensions, and a prior with zero variance outside them makes the posterior certain
    // exactly where it knows nothing. So each training camera is left out in turn and its residual outside the
    // others' mean and span is measured; the per-band mean square of those residuals is added to the prior as
    // independent band-wise variance. (Without it the credible bands covered the truth at 9–85 % of bands for some
    // left-out cameras; see docs/ACCURACY.md.)
    Eigen::VectorXd outside = Eigen::VectorXd::Zero(bands);
    if (ncam >= 3) {
      for (Eigen::Index j = 0; j < ncam; ++j) {
        Eigen::MatrixXd others(bands, ncam - 1);
        for (Eigen::Index i = 0, col = 0; i < ncam; ++i)
          if (i != j) others.col(col++) = M.col(i);
        const Eigen::VectorXd mean_j = others.rowwise().mean();
        others.colwise() -= mean_j;
        Eigen::JacobiSVD<Eigen::MatrixXd> svd_j(others, Eigen::ComputeThinU);
        Eigen::Index kj = 0;
        const auto sv = svd_j.singularValues();
        while (kj < sv.size() && sv(kj) > 1e-9 * std::max(sv(0), 1e-300)) ++kj;
        const Eigen::MatrixXd U = svd_j.matrixU().leftCols(kj);
        const Eigen::VectorXd d = M.col(j) - mean_j;
        outside += (d - U * (U.transpose() * d)).array().square().matrix();
      }
      outside /= static_cast<double>(ncam);
    }
    M.colwise() -= p.mean;
    const Eigen::MatrixXd cov = M * M.transpose() / static_cast<double>(ncam - 1) + Eigen::MatrixXd(outside.asDiagonal());
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(cov);
    const Eigen::VectorXd ev = eig.eigenvalues().reverse();
    const Eigen::MatrixXd ed = eig.eigenvectors().rowwise().reverse();
    Eigen::Index k = 0;
    while (k < ev.size() && ev(k) > 1e-18 * std::max(ev(0), 1e-300)) ++k;  // drop the null space
    p.directions = ed.leftCols(k);
    p.sdev = ev.head(k).cwiseSqrt();
  }
  return prior;
}

namespace {

// Restricted log-likelihood of y under y = a·(X mean) + X U c + e, c ~ N(0, σ²/λ · diag(sdev²)), e ~ N(0, σ²),
// with the amplitude a integrated out (flat prior) and σ² profiled. With P the projector orthogonal to X·mean and
// P X U diag(sdev) = W D Vᵀ, the (n−1)-dimensional covariance I + Z Zᵀ/λ is diagonal in W, so each λ costs O(n k).
struct Reml {
  Eigen::VectorXd d2;   // squared singular values
  Eigen::VectorXd wPy;  // Wᵀ P y
  double Py2 = 0;       // ‖P y‖²
  double m = 0;         // n − 1

  double operator()(double lambda) const {
    double logdet = 0, q = Py2;
    for (Eigen::Index i = 0; i < d2.size(); ++i) {
      logdet += std::log1p(d2(i) / lambda);
      q -= wPy(i) * wPy(i) * d2(i) / (lambda + d2(i));
    }
    q = std::max(q, 1e-300 * std::max(Py2, 1e-300));
    return -0.5 * logdet - 0.5 * m * std::log(q / m);
  }
};

// Lawson & Hanson (1974) ch. 23: least squares with linear inequalities, min ‖E c − f‖ s.t. G c ≥ 0, reduced to a
// least-distance problem and then to NNLS — exact, and reuses the tested NNLS.
Eigen::VectorXd least_squares_nonnegative_image(const Eigen::MatrixXd& E, const Eigen::VectorXd& f, const Eigen::MatrixXd& G) {
  const Eigen::Index k = E.cols();
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(E);
  const Eigen::MatrixXd R = qr.matrixQR().topRows(k).triangularView<Eigen::Upper>();
  const double rmax = R.diagonal().cwiseAbs().maxCoeff();
  if (!(R.diagonal().cwiseAbs().minCoeff() > 1e-12 * rmax))
    throw Error(ErrorClass::bad_data, "black box with prior: design is rank-deficient (spectra do not see the prior's mean curve)");
  const Eigen::VectorXd fq = (qr.householderQ().transpose() * f).head(k);
  // Gt = G R⁻¹, so that with z = R c − fq the constraint reads Gt z ≥ −Gt fq.
  const Eigen::MatrixXd Gt = R.transpose().triangularView<Eigen::Lower>().solve(G.transpose()).transpose();
  const Eigen::VectorXd ht = -Gt * fq;
  Eigen::MatrixXd M(k + 1, G.rows());
  M.topRows(k) = Gt.transpose();
  M.row(k) = ht.transpose();
  Eigen::VectorXd e = Eigen::VectorXd::Zero(k + 1);
  e(k) = 1;
  const Eigen::VectorXd u = nnls(M, e);
  const Eigen::VectorXd r = M * u - e;
  if (!(std::abs(r(k)) > 1e-12))  // cannot happen for G c ≥ 0 (c = 0 is feasible); guards against round-off
    throw Error(ErrorClass::internal, "black box with prior: non-negativity constraints reported incompatible");
  const Eigen::VectorXd z = -r.head(k) / r(k);
  return R.triangularView<Eigen::Upper>().solve(z + fq);
}

}  // namespace

PriorFit fit_with_prior(const ChannelPrior& prior, const Eigen::MatrixXd& X, const Eigen::VectorXd& y) {
  const Eigen::Index bands = X.cols(), n = X.rows(), k = prior.directions.cols();
  if (prior.mean.size() != bands || prior.directions.rows() != bands || prior.sdev.size() != k)
    throw Error(ErrorClass::bad_data, "black box with prior: prior has " + std::to_string(prior.mean.size()) +
                                          " bands, spectra " + std::to_string(bands));
  if (y.size() != n) throw Error(ErrorClass::bad_data, "black box with prior: RAW and spectra differ in length");
  if (n < 3) throw Error(ErrorClass::bad_data, "black box with prior: need at least 3 patches");
  const Eigen::VectorXd a = X * prior.mean;
  if (!(a.squaredNorm() > 0)) throw Error(ErrorClass::bad_data, "black box with prior: spectra are zero where the prior's curve is not");
  auto project = [&](const Eigen::MatrixXd& v) -> Eigen::MatrixXd { return v - a * (a.transpose() * v) / a.squaredNorm(); };

  Reml reml;
  reml.m = static_cast<double>(n - 1);
  const Eigen::VectorXd Py = project(y);
  reml.Py2 = Py.squaredNorm();
  double lambda = 1;
  std::vector<std::pair<double, double>> grid;  // (λ, restricted log-likelihood) — the posterior of λ, for the band
  if (k > 0) {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(project(X * prior.directions * prior.sdev.asDiagonal()), Eigen::ComputeThinU);
    reml.d2 = svd.singularValues().array().square();
    reml.wPy = svd.matrixU().transpose() * Py;
    const double top = std::max(reml.d2(0), 1e-300);
    // Coarse log grid over every regime from "prior ignored" to "mean curve only", then a golden-section polish.
    double best = -std::numeric_limits<double>::infinity();
    const int steps = 97;
    for (int s = 0; s < steps; ++s) {
      const double l = top * std::pow(10.0, -14.0 + 18.0 * s / (steps - 1));
      const double v = reml(l);
      grid.emplace_back(l, v);
      if (v > best) {
        best = v;
        lambda = l;
      }
    }
    double lo = std::log(lambda) - std::log(10.0) * 18.0 / (steps - 1), hi = std::log(lambda) + std::log(10.0) * 18.0 / (steps - 1);
    const double g = (std::sqrt(5.0) - 1) / 2;
    for (int it = 0; it < 40; ++it) {
      const double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
      if (reml(std::exp(x1)) >= reml(std::exp(x2))) hi = x2;
      else lo = x1;
    }
    lambda = std::exp(0.5 * (lo + hi));
  }

  Eigen::MatrixXd B(bands, k + 1);
  B.col(0) = prior.mean;
  B.rightCols(k) = prior.directions;
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(n + k, k + 1);
  E.topRows(n) = X * B;
  for (Eigen::Index i = 0; i < k; ++i) E(n + i, i + 1) = std::sqrt(lambda) / prior.sdev(i);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(n + k);
  f.head(n) = y;
  PriorFit fit;
  fit.lambda = lambda;
  fit.curve = (B * least_squares_nonnegative_image(E, f, B)).cwiseMax(0.0);  // clears round-off below zero
  // The band: at a given λ, θ = (a, c) has a Gaussian posterior with precision EᵀE / σ², σ² at its REML estimate
  // q(λ)/(n − 1). λ itself is uncertain — for some cameras and draws the likelihood has a second mode at a much
  // heavier prior weight, and a band at the single best λ is then far too narrow (it covered the truth at 9 % of the
  // bands for one left-out camera). So λ is integrated out over the grid with a log-uniform prior: the band's
  // variance is the mixture's second moment about the reported curve, Σ_g w_g (var_g + (mean_g − curve)²). The
  // non-negativity constraint is not in the posterior; its effect appears through (mean_g − curve)².
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(k + 1, k + 1);
  auto q_at = [&](double l) {
    double q = reml.Py2;  // y'P(I + ZZ'/λ)⁻¹Py, as in Reml
    for (Eigen::Index i = 0; i < reml.d2.size(); ++i) q -= reml.wPy(i) * reml.wPy(i) * reml.d2(i) / (l + reml.d2(i));
    return std::max(q, 0.0);
  };
  fit.noise_sdev = std::sqrt(q_at(lambda) / reml.m);
  if (grid.empty()) grid.emplace_back(lambda, 0.0);
  double top_ll = -std::numeric_limits<double>::infinity();
  for (const auto& g : grid) top_ll = std::max(top_ll, g.second);
  Eigen::MatrixXd second = Eigen::MatrixXd::Zero(bands, bands);
  double total = 0;
  for (const auto& [l, ll] : grid) {
    const double w = std::exp(ll - top_ll);
    if (w < 1e-8) continue;
    Eigen::MatrixXd Eg = E;
    for (Eigen::Index i = 0; i < k; ++i) Eg(n + i, i + 1) = std::sqrt(l) / prior.sdev(i);
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(Eg.transpose() * Eg);
    const Eigen::VectorXd mean = B * ldlt.solve(Eg.transpose() * f);
    const Eigen::MatrixXd cov = (q_at(l) / reml.m) * ldlt.solve(I);
    const Eigen::VectorXd off = mean - fit.curve;
    second += w * (B * cov * B.transpose() + off * off.transpose());
    total += w;
  }
  fit.covariance = second / total;
  fit.sdev = fit.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  return fit;
}

CurveBand credible_band(const Eigen::VectorXd& curve, const Eigen::VectorXd& sdev, double z) {
  if (curve.size() != sdev.size()) throw Error(ErrorClass::bad_data, "credible band: curve and its standard deviation differ in length");
  return {(curve - z * sdev).cwiseMax(0.0), curve + z * sdev};
}

}  // namespace colorlab::analysis
