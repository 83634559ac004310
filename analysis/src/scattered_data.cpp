#include "colorlab/analysis/scattered_data.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "colorlab/core/error.hpp"

namespace colorlab::analysis {

namespace {
constexpr const char* kPrefix = "rbf:";

Eigen::MatrixXd cube_root_coordinates(const Eigen::MatrixXd& rgb, double scale) {
  return (rgb / scale).unaryExpr([](double v) { return std::cbrt(std::max(v, 0.0)); });
}

Eigen::MatrixXd cubic_kernel(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  Eigen::MatrixXd k(a.rows(), b.rows());
  for (Eigen::Index i = 0; i < a.rows(); ++i)
    for (Eigen::Index j = 0; j < b.rows(); ++j) k(i, j) = std::pow((a.row(i) - b.row(j)).norm(), 3);
  return k;
}

// The training kernel: symmetric, so each pair's pow once (‖u − v‖ and ‖v − u‖ are the same number to the bit).
Eigen::MatrixXd cubic_kernel(const Eigen::MatrixXd& a) {
  Eigen::MatrixXd k(a.rows(), a.rows());
  for (Eigen::Index i = 0; i < a.rows(); ++i) {
    k(i, i) = 0;
    for (Eigen::Index j = i + 1; j < a.rows(); ++j) k(i, j) = k(j, i) = std::pow((a.row(i) - a.row(j)).norm(), 3);
  }
  return k;
}

// The base terms plus the constant and linear coordinate terms the r³ kernel needs; a constant already in the base
// is not repeated (a duplicate column would make the system singular).
Eigen::MatrixXd polynomial_part(const TermSet& base, const Eigen::MatrixXd& rgb_scaled, const Eigen::MatrixXd& u) {
  bool has_constant = false;
  for (const auto& t : base.terms)
    if (t.exponent == std::array<double, 3>{0, 0, 0}) has_constant = true;
  const Eigen::MatrixXd b = expand_terms(base, rgb_scaled);
  Eigen::MatrixXd p(b.rows(), b.cols() + (has_constant ? 0 : 1) + 3);
  p.leftCols(b.cols()) = b;
  if (!has_constant) p.col(b.cols()).setOnes();
  p.rightCols(3) = u;
  return p;
}

Eigen::MatrixXd target_of(const ChartData& d, FitTarget t) { return t == FitTarget::lab_direct ? d.lab : d.xyz; }

// One smoothing value: the saddle-point system [K + λ W⁻², P; Pᵀ, 0] [c; d] = [y; 0], solved once for the
// coefficients and once for the hat matrix H = [K P] A⁻¹[:, :n]. Nothing in it is normalised by the training set (not
// n, not the weights' mean, not K's scale): the model with patch i left out is then the same problem without row i,
// which is what makes e_i / (1 − h_ii) its exact held-out residual.
struct Solved {
  Eigen::MatrixXd c, d, fitted;
  Eigen::VectorXd leverage;
  double trace = 0;
};

Solved solve_at(const Eigen::MatrixXd& K, const Eigen::MatrixXd& P, const Eigen::VectorXd& w, const Eigen::MatrixXd& Y,
                double lambda, bool want_hat) {
  const Eigen::Index n = K.rows(), m = P.cols();
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n + m, n + m);
  A.topLeftCorner(n, n) = K;
  A.topLeftCorner(n, n).diagonal() += lambda * w.array().square().inverse().matrix();
  A.topRightCorner(n, m) = P;
  A.bottomLeftCorner(m, n) = P.transpose();
  Eigen::PartialPivLU<Eigen::MatrixXd> lu(A);
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n + m, Y.cols());
  rhs.topRows(n) = Y;
  const Eigen::MatrixXd sol = lu.solve(rhs);
  Solved s;
  s.c = sol.topRows(n);
  s.d = sol.bottomRows(m);
  s.fitted = K * s.c + P * s.d;
  if (want_hat) {
    Eigen::MatrixXd e = Eigen::MatrixXd::Zero(n + m, n);
    e.topRows(n).setIdentity();
    const Eigen::MatrixXd inv = lu.solve(e);  // A⁻¹[:, :n]
    const Eigen::MatrixXd H = K * inv.topRows(n) + P * inv.bottomRows(m);
    s.leverage = H.diagonal();
    s.trace = s.leverage.sum();
  }
  return s;
}

// Every λ at the cost of one decomposition. With P = [Q₁ Q₂]R (Q₂ spans the coefficients the side condition Pᵀc = 0
// allows) and D = W⁻², c = Q₂ a solves Q₂ᵀ(K + λD)Q₂ a = Q₂ᵀy. The generalised eigenproblem Q₂ᵀKQ₂ v = μ Q₂ᵀDQ₂ v
// (VᵀQ₂ᵀDQ₂V = I) diagonalises that system for every λ at once: with G = Q₂V, c = G diag(1/(μ+λ)) Gᵀy, the residual
// y − f = λDc, and 1 − h_ii = λ D_ii Σ_k G_ik² / (μ_k + λ). A λ then costs O(n²) instead of an LU and an n-column
// solve, which is what the 41-value search spent its time on (docs/PERFORMANCE.md, issue 26).
class Smoother {
 public:
  Smoother(const Eigen::MatrixXd& K, const Eigen::MatrixXd& P, const Eigen::VectorXd& w, const Eigen::MatrixXd& Y)
      : K_(K), Y_(Y), qr_(P), d_(w.array().square().inverse().matrix()) {
    const Eigen::Index n = K.rows(), m = P.cols();
    const Eigen::MatrixXd Q = qr_.householderQ() * Eigen::MatrixXd::Identity(n, n);
    const Eigen::MatrixXd Q2 = Q.rightCols(n - m);
    Eigen::MatrixXd A = Q2.transpose() * K * Q2;
    A = 0.5 * (A + A.transpose()).eval();
    Eigen::MatrixXd B = Q2.transpose() * d_.asDiagonal() * Q2;
    B = 0.5 * (B + B.transpose()).eval();
    const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(A, B, Eigen::ComputeEigenvectors | Eigen::Ax_lBx);
    if (eig.info() != Eigen::Success) throw Error(ErrorClass::bad_data, "spline: the smoothing eigenproblem did not converge");
    mu_ = eig.eigenvalues();
    G_ = Q2 * eig.eigenvectors();
    z_ = G_.transpose() * Y;
    g2_ = G_.array().square().matrix();
  }

  Solved at(double lambda, bool want_hat, bool want_coefficients) const {
    const Eigen::VectorXd inv = (mu_.array() + lambda).inverse().matrix();
    Solved s;
    s.c = G_ * (inv.asDiagonal() * z_);
    s.fitted = Y_ - lambda * (d_.asDiagonal() * s.c);
    if (want_coefficients) s.d = qr_.solve(Eigen::MatrixXd(s.fitted - K_ * s.c));
    if (want_hat) {
      s.leverage = Eigen::VectorXd::Ones(Y_.rows()) - lambda * d_.cwiseProduct(g2_ * inv);
      s.trace = s.leverage.sum();
    }
    return s;
  }

 private:
  const Eigen::MatrixXd& K_;
  const Eigen::MatrixXd& Y_;
  Eigen::HouseholderQR<Eigen::MatrixXd> qr_;
  Eigen::VectorXd d_, mu_;
  Eigen::MatrixXd G_, z_, g2_;
};

double mean_de00(const Eigen::MatrixXd& pred_target, const ChartData& d, FitTarget t) {
  const Eigen::MatrixXd lab = t == FitTarget::lab_direct ? pred_target : xyz_rows_to_lab(pred_target, d.white);
  return evaluate(lab, d.lab).s00.mean;
}

Eigen::MatrixXd loo_predictions(const Solved& s, const Eigen::MatrixXd& Y) {
  Eigen::MatrixXd pred = Eigen::MatrixXd::Constant(Y.rows(), Y.cols(), std::numeric_limits<double>::quiet_NaN());
  for (Eigen::Index i = 0; i < Y.rows(); ++i) {
    const double denom = 1 - s.leverage(i);
    if (denom > 1e-10) pred.row(i) = Y.row(i) - (Y.row(i) - s.fitted.row(i)) / denom;
  }
  return pred;
}
}  // namespace

bool is_spline_method(const std::string& method) { return method.rfind(kPrefix, 0) == 0; }
std::string spline_method(const std::string& base) { return kPrefix + base; }

SplineOptions spline_options(const std::string& method, const FitOptions& o) {
  if (!is_spline_method(method)) throw Error(ErrorClass::bad_parameter, "method '" + method + "' is not rbf:<term set>");
  SplineOptions so;
  so.base = method.substr(std::string(kPrefix).size());
  term_set_by_name(so.base);  // validates the base's name now, with its own message
  so.target = o.target;
  so.input_scale = o.input_scale;
  so.search = o.spline_search;
  return so;
}

// The model and the smoother's solution at the λ used (its leverages give the exact LOO residuals).
struct FitWithHat {
  SplineModel model;
  Solved solved;
};

struct SplineFitter {
  static FitWithHat fit(const ChartData& train, const SplineOptions& o);
};

FitWithHat SplineFitter::fit(const ChartData& train, const SplineOptions& o) {
  SplineModel model;
  model.base_ = term_set_by_name(o.base);
  model.method_ = spline_method(o.base);
  model.target_ = o.target;
  model.white_ = train.white;
  model.input_scale_ = o.input_scale > 0 ? o.input_scale : (train.rgb.maxCoeff() > 0 ? train.rgb.maxCoeff() : 1.0);
  const Eigen::MatrixXd scaled = train.rgb / model.input_scale_;
  model.centres_ = cube_root_coordinates(train.rgb, model.input_scale_);
  const Eigen::MatrixXd K = cubic_kernel(model.centres_);
  const Eigen::MatrixXd P = polynomial_part(model.base_, scaled, model.centres_);
  const Eigen::Index n = K.rows();
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(P);
  qr.setThreshold(1e-10);
  if (P.cols() >= n || qr.rank() < P.cols())
    throw Error(ErrorClass::bad_data,
                model.method_ + ": " + std::to_string(n) + " patches cannot determine the base's " +
                    std::to_string(P.cols()) + " terms (rank " + std::to_string(qr.rank()) + ")",
                "use a smaller base (rbf:ccm) or more distinct patches");
  const Eigen::VectorXd w = target_weights(train, o.target);
  const Eigen::MatrixXd Y = target_of(train, o.target);

  // A fixed λ is one solve; the search decomposes once (eigen) or solves at every λ (direct, the reference).
  std::optional<Smoother> smoother;
  if (!o.smoothing && o.search == SmoothingSearch::eigen) smoother.emplace(K, P, w, Y);
  auto solve = [&](double l, bool want_coefficients, bool want_hat = true) {
    return smoother ? smoother->at(l, true, want_coefficients) : solve_at(K, P, w, Y, l, want_hat);
  };
  double lambda = o.smoothing.value_or(0);
  if (!o.smoothing) {
    double best = std::numeric_limits<double>::infinity();
    const int steps = std::max(2, o.smoothing_steps);
    std::vector<std::pair<double, double>> scores;
    for (int k = 0; k < steps; ++k) {
      const double l = o.smoothing_min * std::pow(o.smoothing_max / o.smoothing_min, k / double(steps - 1));
      const double e = mean_de00(loo_predictions(solve(l, false), Y), train, o.target);
      scores.emplace_back(l, e);
      if (e < best) {
        best = e;
        lambda = l;
      }
    }
    double tol = o.smoothing_tolerance.value_or(0);
    if (!o.smoothing_tolerance) {
      const Eigen::MatrixXd pr = loo_predictions(solve(lambda, false), Y);
      const auto ev = evaluate(o.target == FitTarget::lab_direct ? pr : xyz_rows_to_lab(pr, train.white), train.lab);
      tol = ev.s00.stdev / std::sqrt(static_cast<double>(n));
    }
    for (const auto& [l, e] : scores)
      if (e <= best + tol && l > lambda) lambda = l;
    if (!std::isfinite(best))
      throw Error(ErrorClass::bad_data, model.method_ + ": no smoothing value gives finite leave-one-out errors");
  }
  const bool want_hat = o.hat_matrix || !o.smoothing;  // a search has it anyway
  Solved s = solve(lambda, true, want_hat);
  model.smoothing_ = lambda;
  model.kernel_ = s.c;
  model.poly_ = s.d;
  model.dof_ = want_hat ? s.trace : std::numeric_limits<double>::quiet_NaN();
  return {std::move(model), std::move(s)};
}

SplineModel fit_spline(const ChartData& train, const SplineOptions& o) {
  train.check();
  return SplineFitter::fit(train, o).model;
}

Eigen::MatrixXd SplineModel::predict_target(const Eigen::MatrixXd& rgb) const {
  const Eigen::MatrixXd u = cube_root_coordinates(rgb, input_scale_);
  return cubic_kernel(u, centres_) * kernel_ + polynomial_part(base_, rgb / input_scale_, u) * poly_;
}

std::string SplineModel::describe() const {
  return "r^3 spline on cube-root RGB over " + base_.name + " + 1 + cube-root terms (lambda " + std::to_string(smoothing_) + ", " +
         std::to_string(dof_) + " effective parameters per channel, " + std::to_string(centres_.rows()) + " centres)";
}

Eigen::MatrixXd SplineModel::apply(const Eigen::MatrixXd& rgb) const {
  const Eigen::MatrixXd t = predict_target(rgb);
  return target_ == FitTarget::lab_direct ? t : xyz_rows_to_lab(t, white_);
}

Eigen::MatrixXd spline_loo_targets(const ChartData& data, const SplineOptions& o) {
  data.check();
  if (!o.smoothing) throw Error(ErrorClass::bad_parameter, "spline_loo_targets needs the smoothing λ");
  const double scale = o.input_scale > 0 ? o.input_scale : (data.rgb.maxCoeff() > 0 ? data.rgb.maxCoeff() : 1.0);
  const Eigen::MatrixXd u = cube_root_coordinates(data.rgb, scale);
  const Eigen::MatrixXd K = cubic_kernel(u);
  const Eigen::MatrixXd P = polynomial_part(term_set_by_name(o.base), data.rgb / scale, u);
  const Eigen::MatrixXd Y = target_of(data, o.target);
  return loo_predictions(solve_at(K, P, target_weights(data, o.target), Y, *o.smoothing, true), Y);
}

FitReport spline_report(const ChartData& data, const SplineOptions& o, const CvSpec& cv) {
  data.check();
  FitReport r;
  r.method = spline_method(o.base);
  r.target = o.target;
  r.cv_name = cv.name();
  const auto n = static_cast<Eigen::Index>(data.size());
  const Eigen::MatrixXd Y = target_of(data, o.target);
  Eigen::MatrixXd pred = Eigen::MatrixXd::Constant(n, 3, std::numeric_limits<double>::quiet_NaN());
  try {
    SplineOptions with_hat = o;
    with_hat.hat_matrix = true;
    const FitWithHat fitted = SplineFitter::fit(data, with_hat);
    const SplineModel& model = fitted.model;
    r.terms = model.base_terms();
    r.parameters = model.effective_parameters();
    r.training = evaluate(model.apply(data.rgb), data.lab);
    if (cv.kind == CvSpec::Kind::none) {
      pred = model.predict_target(data.rgb);
    } else if (cv.kind == CvSpec::Kind::leave_one_out) {
      pred = loo_predictions(fitted.solved, Y);  // at the λ chosen on all patches
    }
  } catch (const Error&) {
    r.rank_deficient = true;
    const std::vector<double> inf(data.size(), std::numeric_limits<double>::infinity());
    r.training = evaluate(Eigen::MatrixXd::Constant(n, 3, std::numeric_limits<double>::quiet_NaN()), data.lab);
    r.parameters = std::numeric_limits<double>::infinity();
  }
  if (cv.kind == CvSpec::Kind::k_fold) {
    if (cv.folds < 2 || cv.folds > n)
      throw Error(ErrorClass::bad_parameter, std::to_string(cv.folds) + "-fold cross-validation on " + std::to_string(n) + " patches");
    std::vector<std::size_t> order(static_cast<std::size_t>(n));
    std::iota(order.begin(), order.end(), 0);
    std::mt19937 rng(cv.seed);
    std::shuffle(order.begin(), order.end(), rng);
    SplineOptions fo = o;
    fo.input_scale = o.input_scale > 0 ? o.input_scale : data.rgb.maxCoeff();
    for (int f = 0; f < cv.folds; ++f) {
      std::vector<std::size_t> train, test;
      for (std::size_t i = 0; i < order.size(); ++i)
        (static_cast<int>(i % static_cast<std::size_t>(cv.folds)) == f ? test : train).push_back(order[i]);
      try {
        const SplineModel m = fit_spline(data.subset(train), fo);  // λ chosen inside the fold: nested
        const Eigen::MatrixXd p = m.predict_target(data.subset(test).rgb);
        for (std::size_t i = 0; i < test.size(); ++i) pred.row(static_cast<Eigen::Index>(test[i])) = p.row(static_cast<Eigen::Index>(i));
      } catch (const Error&) {
        // This fold's training patches cannot determine the base: its patches stay unpredicted.
      }
    }
  }
  r.cv = evaluate(o.target == FitTarget::lab_direct ? pred : xyz_rows_to_lab(pred, data.white), data.lab);
  return r;
}

}  // namespace colorlab::analysis
