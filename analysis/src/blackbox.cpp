#include "colorlab/analysis/blackbox.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "colorlab/core/error.hpp"

namespace colorlab::analysis {

Eigen::VectorXd nnls(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, int max_iterations) {
  const Eigen::Index m = A.rows(), n = A.cols();
  if (b.size() != m) throw Error(ErrorClass::bad_data, "NNLS: right-hand side has " + std::to_string(b.size()) +
                                                           " rows, matrix " + std::to_string(m));
  if (!A.allFinite() || !b.allFinite()) throw Error(ErrorClass::bad_data, "NNLS: input contains NaN or infinity");
  if (max_iterations <= 0) max_iterations = static_cast<int>(3 * n + 30);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  std::vector<bool> passive(static_cast<std::size_t>(n), false);
  const double tol = 10 * std::numeric_limits<double>::epsilon() * A.cwiseAbs().colwise().sum().maxCoeff() * std::max(m, n);
  auto solve_passive = [&](Eigen::VectorXd& z) {
    std::vector<Eigen::Index> idx;
    for (Eigen::Index j = 0; j < n; ++j)
      if (passive[static_cast<std::size_t>(j)]) idx.push_back(j);
    Eigen::MatrixXd Ap(m, static_cast<Eigen::Index>(idx.size()));
    for (std::size_t k = 0; k < idx.size(); ++k) Ap.col(static_cast<Eigen::Index>(k)) = A.col(idx[k]);
    Eigen::VectorXd zp = Ap.colPivHouseholderQr().solve(b);
    z.setZero(n);
    for (std::size_t k = 0; k < idx.size(); ++k) z(idx[k]) = zp(static_cast<Eigen::Index>(k));
  };
  for (int outer = 0; outer < max_iterations; ++outer) {
    Eigen::VectorXd w = A.transpose() * (b - A * x);
    Eigen::Index best = -1;
    double wmax = tol;
    for (Eigen::Index j = 0; j < n; ++j)
      if (!passive[static_cast<std::size_t>(j)] && w(j) > wmax) {
        wmax = w(j);
        best = j;
      }
    if (best < 0) return x;  // Kuhn–Tucker conditions hold
    passive[static_cast<std::size_t>(best)] = true;
    Eigen::VectorXd z;
    for (int inner = 0; inner < max_iterations; ++inner) {
      solve_passive(z);
      bool feasible = true;
      for (Eigen::Index j = 0; j < n; ++j)
        if (passive[static_cast<std::size_t>(j)] && z(j) <= 0) feasible = false;
      if (feasible) break;
      double alpha = 1;
      for (Eigen::Index j = 0; j < n; ++j)
        if (passive[static_cast<std::size_t>(j)] && z(j) <= 0) alpha = std::min(alpha, x(j) / (x(j) - z(j)));
      x += alpha * (z - x);
      for (Eigen::Index j = 0; j < n; ++j)
        if (passive[static_cast<std::size_t>(j)] && x(j) <= tol) {
          passive[static_cast<std::size_t>(j)] = false;
          x(j) = 0;
        }
    }
    x = z;
  }
  throw Error(ErrorClass::internal, "NNLS did not converge in " + std::to_string(max_iterations) + " iterations");
}

namespace {
Eigen::MatrixXd second_difference(Eigen::Index n) {
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(std::max<Eigen::Index>(n - 2, 0), n);
  for (Eigen::Index i = 0; i + 2 < n; ++i) {
    D(i, i) = 1;
    D(i, i + 1) = -2;
    D(i, i + 2) = 1;
  }
  return D;
}

// GCV(λ) = n‖(I − H)y‖² / tr(I − H)² for the unconstrained penalised smoother H = X(XᵀX + λDᵀD)⁻¹Xᵀ; the
// non-negativity constraint is then imposed at the chosen λ.
double gcv_lambda(const Eigen::MatrixXd& X, const Eigen::VectorXd& y, const Eigen::MatrixXd& D, double scale,
                  const BlackBoxOptions& o) {
  const double n = static_cast<double>(X.rows());
  double best = o.lambda_min, best_score = std::numeric_limits<double>::infinity();
  const Eigen::MatrixXd XtX = X.transpose() * X, DtD = D.transpose() * D;
  const Eigen::VectorXd Xty = X.transpose() * y;
  for (int k = 0; k < o.lambda_steps; ++k) {
    double rel = o.lambda_min * std::pow(o.lambda_max / o.lambda_min, k / double(std::max(1, o.lambda_steps - 1)));
    Eigen::MatrixXd K = XtX + rel * scale * DtD;
    Eigen::LDLT<Eigen::MatrixXd> ldlt(K);
    if (ldlt.info() != Eigen::Success) continue;
    Eigen::VectorXd s = ldlt.solve(Xty);
    double rss = (y - X * s).squaredNorm();
    double tr = (ldlt.solve(XtX)).trace();
    double denom = n - tr;
    if (denom <= 0) continue;
    double score = n * rss / (denom * denom);
    if (score < best_score) {
      best_score = score;
      best = rel;
    }
  }
  return best;
}
}  // namespace

BlackBoxModel fit_blackbox(const Eigen::MatrixXd& spectra, const Eigen::MatrixXd& raw, const BlackBoxOptions& o) {
  if (spectra.rows() != raw.rows())
    throw Error(ErrorClass::bad_data, "black box: " + std::to_string(spectra.rows()) + " spectra but " +
                                          std::to_string(raw.rows()) + " RAW triples");
  if (raw.cols() != 3) throw Error(ErrorClass::bad_data, "black box: RAW values need 3 columns");
  if (spectra.rows() < 3 || spectra.cols() < 3) throw Error(ErrorClass::bad_data, "black box: too few spectra or bands");
  if (!spectra.allFinite() || !raw.allFinite()) throw Error(ErrorClass::bad_data, "black box: input contains NaN");
  if ((spectra.array() < 0).any()) throw Error(ErrorClass::bad_data, "black box: negative spectral values");
  const Eigen::Index m = spectra.cols();
  // Column scaling keeps the penalty weight meaningful whatever the radiance units.
  const double xscale = spectra.maxCoeff() > 0 ? spectra.maxCoeff() : 1.0;
  const Eigen::MatrixXd X = spectra / xscale;
  const Eigen::MatrixXd D = second_difference(m);
  const double scale = X.squaredNorm() / std::max(1.0, D.squaredNorm());
  BlackBoxModel model;
  model.sensitivities.resize(3, m);
  if (o.prior) {
    if (o.prior->wavelengths.size() != static_cast<std::size_t>(m))
      throw Error(ErrorClass::bad_data, "black box: prior has " + std::to_string(o.prior->wavelengths.size()) +
                                            " bands, spectra " + std::to_string(m));
    model.with_prior = true;
    model.sensitivity_sdev.resize(3, m);
    for (int c = 0; c < 3; ++c) {
      PriorFit fit = fit_with_prior(o.prior->channels[static_cast<std::size_t>(c)], X, raw.col(c));
      model.lambda[static_cast<std::size_t>(c)] = fit.lambda;
      model.sensitivities.row(c) = fit.curve.transpose() / xscale;
      model.sensitivity_sdev.row(c) = fit.sdev.transpose() / xscale;
      model.sensitivity_covariance[static_cast<std::size_t>(c)] = fit.covariance / (xscale * xscale);
    }
    return model;
  }
  for (int c = 0; c < 3; ++c) {
    Eigen::VectorXd y = raw.col(c);
    double lambda = 0;
    if (o.smoothness) lambda = o.lambda ? *o.lambda : gcv_lambda(X, y, D, scale, o);
    model.lambda[static_cast<std::size_t>(c)] = lambda;
    Eigen::MatrixXd A(X.rows() + (lambda > 0 ? D.rows() : 0), m);
    Eigen::VectorXd b = Eigen::VectorXd::Zero(A.rows());
    A.topRows(X.rows()) = X;
    b.head(X.rows()) = y;
    if (lambda > 0) A.bottomRows(D.rows()) = std::sqrt(lambda * scale) * D;
    model.sensitivities.row(c) = nnls(A, b).transpose() / xscale;
  }
  return model;
}

Eigen::MatrixXd BlackBoxModel::predict(const Eigen::MatrixXd& spectra) const {
  if (spectra.cols() != sensitivities.cols())
    throw Error(ErrorClass::bad_data, "black box: spectra have " + std::to_string(spectra.cols()) + " bands, model " +
                                          std::to_string(sensitivities.cols()));
  return spectra * sensitivities.transpose();
}

ResidualTable blackbox_residuals(const BlackBoxModel& model, const Eigen::MatrixXd& spectra, const Eigen::MatrixXd& raw,
                                 double full_scale) {
  if (!(full_scale > 0)) throw Error(ErrorClass::bad_parameter, "full scale must be positive");
  ResidualTable t;
  t.residuals = model.predict(spectra) - raw;
  for (int c = 0; c < 3; ++c) {
    std::vector<double> a, p;
    for (Eigen::Index i = 0; i < t.residuals.rows(); ++i) {
      a.push_back(std::abs(t.residuals(i, c)));
      p.push_back(100.0 * std::abs(t.residuals(i, c)) / full_scale);
    }
    t.counts[static_cast<std::size_t>(c)] = summarize(a);
    t.percent[static_cast<std::size_t>(c)] = summarize(p);
  }
  return t;
}

}  // namespace colorlab::analysis
