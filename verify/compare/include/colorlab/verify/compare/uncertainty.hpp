#pragma once
// The measurement's own uncertainty, source by source, and the verdict it allows (issue 23, docs/verify.md
// "Comparing and the uncertainty"). Every compared quantity is a vector (a colour's three coordinates, a spot's
// one luminance); each source of the measurement chain contributes a covariance to it, and the difference between
// rendering and measurement is judged by its Mahalanobis distance under their sum. "k = 2" is read as its
// coverage probability (95.45 % for one dimension) carried to the quantity's dimension, so a 3-D colour is not
// judged with a band that covers only 87 % of its own noise.
#include <Eigen/Dense>
#include <string>
#include <vector>

namespace colorlab::verify {

inline constexpr double kCoverageK = 2.0;

// The probability a normal quantity falls within ±k standard deviations (0.9545 for k = 2).
double coverage_probability(double k);
// The chi-square quantile with `dof` degrees of freedom at probability p (bisection on the CDF).
double chi_square_quantile(double p, int dof);

struct UncertaintySource {
  std::string name;            // "characterization", "frame noise", "ls110 repeatability", "lamp drift", "misregistration", …
  Eigen::MatrixXd covariance;  // in the compared quantity's coordinates
};

struct Budget {
  std::vector<UncertaintySource> sources;

  void add(std::string name, Eigen::MatrixXd covariance);
  // A source that moves the quantity along one vector with standard deviation 1 (covariance v vᵀ); adding the same
  // name twice sums the covariances (independent parts of one source, e.g. the x and y shift of a misregistration).
  void add_vector(const std::string& name, const Eigen::VectorXd& v);
  Eigen::MatrixXd total(int dim) const;
  // Standard uncertainty each source contributes along the direction `d` (unit vector), for the per-source table.
  std::vector<std::pair<std::string, double>> along(const Eigen::VectorXd& direction) const;
};

struct Judgement {
  double mahalanobis = 0;  // √(Δᵀ Σ⁻¹ Δ)
  double threshold = 0;    // √(chi-square quantile at k = 2's coverage, dof = dimension)
  bool differs = false;    // mahalanobis > threshold
  // The expanded uncertainty along the difference: how far the quantity may move that way and still agree,
  // in the difference's own units (|Δ| · threshold / mahalanobis). Equal to k·u for one dimension.
  double expanded_along = 0;
};

// Throws Error(bad_data) for a covariance that is not positive definite (a budget with no sources at all).
Judgement judge(const Eigen::VectorXd& difference, const Eigen::MatrixXd& covariance, double k = kCoverageK);

}  // namespace colorlab::verify
