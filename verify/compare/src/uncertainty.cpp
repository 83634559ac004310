#include "colorlab/verify/compare/uncertainty.hpp"

#include <cmath>
#include <map>
#include <mutex>
#include <utility>

#include "colorlab/core/error.hpp"

namespace colorlab::verify {

double coverage_probability(double k) { return std::erf(k / std::sqrt(2.0)); }

namespace {

// The regularised lower incomplete gamma P(a, x) by its series (converges for every x; dof here is 1–3).
double gamma_p(double a, double x) {
  if (x <= 0) return 0;
  double term = 1.0 / a, sum = term;
  for (int n = 1; n < 1000; ++n) {
    term *= x / (a + n);
    sum += term;
    if (term < sum * 1e-15) break;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

}  // namespace

double chi_square_quantile(double p, int dof) {
  if (dof < 1 || !(p > 0 && p < 1))
    throw Error(ErrorClass::bad_parameter, "chi-square quantile needs dof >= 1 and 0 < p < 1");
  // Every verdict asks for the same few (k = 2 in 1 and 3 dimensions): remembered, not bisected again each time.
  static std::mutex mutex;
  static std::map<std::pair<double, int>, double> known;
  {
    const std::lock_guard lock(mutex);
    if (const auto it = known.find({p, dof}); it != known.end()) return it->second;
  }
  double lo = 0, hi = 10.0 * dof + 100.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (gamma_p(0.5 * dof, 0.5 * mid) < p ? lo : hi) = mid;
  }
  const std::lock_guard lock(mutex);
  if (known.size() < 64) known[{p, dof}] = 0.5 * (lo + hi);
  return 0.5 * (lo + hi);
}

void Budget::add(std::string name, Eigen::MatrixXd covariance) {
  for (auto& s : sources)
    if (s.name == name) {
      s.covariance += covariance;
      return;
    }
  sources.push_back({std::move(name), std::move(covariance)});
}

void Budget::add_vector(const std::string& name, const Eigen::VectorXd& v) { add(name, v * v.transpose()); }

Eigen::MatrixXd Budget::total(int dim) const {
  Eigen::MatrixXd t = Eigen::MatrixXd::Zero(dim, dim);
  for (const auto& s : sources) t += s.covariance;
  return t;
}

std::vector<std::pair<std::string, double>> Budget::along(const Eigen::VectorXd& direction) const {
  std::vector<std::pair<std::string, double>> out;
  for (const auto& s : sources) {
    const double var = direction.dot(s.covariance * direction);
    out.emplace_back(s.name, std::sqrt(std::max(0.0, var)));
  }
  return out;
}

Judgement judge(const Eigen::VectorXd& difference, const Eigen::MatrixXd& covariance, double k) {
  const auto dim = static_cast<int>(difference.size());
  if (covariance.rows() != dim || covariance.cols() != dim || !(covariance.trace() > 0))
    throw Error(ErrorClass::bad_data, "the measurement's uncertainty is empty or has the wrong shape",
                "every compared quantity needs at least one uncertainty source");
  // A budget whose sources all lie in a plane (e.g. one mapping's errors all along one hue) is still a statement
  // about every direction: a ridge far below any source keeps it invertible without widening the band.
  const Eigen::MatrixXd cov = covariance + Eigen::MatrixXd::Identity(dim, dim) * (1e-12 * covariance.trace());
  Eigen::LLT<Eigen::MatrixXd> llt(cov);
  if (llt.info() != Eigen::Success)
    throw Error(ErrorClass::bad_data, "the measurement's uncertainty is not positive definite",
                "every compared quantity needs at least one uncertainty source in each of its coordinates");
  Judgement j;
  j.mahalanobis = std::sqrt(std::max(0.0, difference.dot(llt.solve(difference))));
  j.threshold = std::sqrt(chi_square_quantile(coverage_probability(k), dim));
  j.differs = j.mahalanobis > j.threshold;
  const double norm = difference.norm();
  if (j.mahalanobis > 0) {
    j.expanded_along = norm * j.threshold / j.mahalanobis;
  } else {
    // No difference at all: the band's half-width along the direction of largest uncertainty.
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(cov);
    j.expanded_along = j.threshold * std::sqrt(es.eigenvalues().maxCoeff());
  }
  return j;
}

}  // namespace colorlab::verify
