#pragma once
// Chapter 7 (d), "black box": RAW_c = Σ s_c(λ)·x(λ) with s ≥ 0, fitted as non-negative least squares with a
// second-difference smoothness penalty whose weight is chosen by generalised cross-validation.
#include <Eigen/Dense>
#include <array>
#include <optional>
#include <vector>

#include "colorlab/analysis/sensitivity_prior.hpp"
#include "colorlab/analysis/statistics.hpp"

namespace colorlab::analysis {

// Lawson & Hanson (1974) active-set NNLS: argmin ‖A x − b‖ subject to x ≥ 0.
Eigen::VectorXd nnls(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, int max_iterations = 0);

struct BlackBoxOptions {
  double full_scale = 4095;      // RAW counts at saturation (12-bit Canon 20D)
  bool smoothness = true;        // second-difference penalty
  std::optional<double> lambda;  // relative penalty weight; unset = chosen by GCV per channel
  double lambda_min = 1e-9, lambda_max = 1e2;
  int lambda_steps = 45;
  // When set, the curves are fitted under a prior learned from other cameras' measured curves instead of the
  // second-difference penalty (see sensitivity_prior.hpp for why); its grid must be the spectra's grid.
  std::optional<SensitivityPrior> prior;
};

struct BlackBoxModel {
  Eigen::MatrixXd sensitivities;   // 3 × bands (R, G, B)
  std::array<double, 3> lambda{};  // penalty weights used: relative smoothness weight, or the prior's λ
  bool with_prior = false;
  // With a prior: 3 × bands posterior standard deviations of `sensitivities` (see PriorFit::sdev); credible_band()
  // turns a row into a band. Empty without a prior: the smoothness penalty has no calibrated posterior.
  Eigen::MatrixXd sensitivity_sdev;
  // With a prior: per channel, the bands × bands posterior covariance (sdev² on its diagonal), for drawing curves.
  std::array<Eigen::MatrixXd, 3> sensitivity_covariance;
  Eigen::MatrixXd predict(const Eigen::MatrixXd& spectra) const;  // n × bands → n × 3 RAW
};

// spectra: n × bands (radiance or illuminant × reflectance, any positive scale); raw: n × 3 counts.
BlackBoxModel fit_blackbox(const Eigen::MatrixXd& spectra, const Eigen::MatrixXd& raw, const BlackBoxOptions& options = {});

// Table 13: per channel, summary of |residual| in counts and in % of full scale.
struct ResidualTable {
  Eigen::MatrixXd residuals;  // n × 3, predicted − measured, counts
  std::array<Summary, 3> counts, percent;
};
ResidualTable blackbox_residuals(const BlackBoxModel& model, const Eigen::MatrixXd& spectra, const Eigen::MatrixXd& raw,
                                 double full_scale);

}  // namespace colorlab::analysis
