#pragma once
// A statistical prior for camera spectral sensitivities, learned from the measured curves of OTHER cameras
// (Jiang, Liu, Gu & Süsstrunk, WACV 2013: a handful of principal components per channel describe real cameras).
//
// Why a prior at all: the §7.4 black box sees the curves only through chart radiances, and a 140-patch SG under one
// lamp has about 8 useful singular values out of 33 bands (colorimetry-notes §5). A second-difference penalty
// supplies the missing directions with "smooth", which is the wrong answer where real curves have steep edges
// (the Canon 20D blue channel rises from 13 % to 64 % of peak in 10 nm). Measured cameras supply them with "what
// cameras actually look like". The curves file is an input the user supplies; nothing is compiled in.
#include <Eigen/Dense>
#include <array>
#include <string>
#include <vector>

#include "colorlab/analysis/spectral.hpp"

namespace colorlab::analysis {

// Gaussian model of one channel's peak-normalised curve: s = mean + directions · c, c_i ~ N(0, sdev_i²).
struct ChannelPrior {
  Eigen::VectorXd mean;        // bands
  Eigen::MatrixXd directions;  // bands × k, orthonormal principal directions of the centred training curves
  Eigen::VectorXd sdev;        // k, standard deviation of the training curves along each direction
};

struct SensitivityPrior {
  std::vector<double> wavelengths;       // the grid the prior was resampled to (the fit's spectral grid)
  std::array<ChannelPrior, 3> channels;  // R, G, B
  std::vector<std::string> cameras;      // cameras that went into it, for reports
};

// curves: one sample per camera channel, named "<camera>_R", "<camera>_G", "<camera>_B" (the layout of the camspec
// and rawtoaces collections), or just "R", "G", "B" for a single camera. Cameras whose name is in `exclude`
// (exact match) are left out — a validation against a camera must not learn from that camera. Needs at least three
// complete cameras; the curves are resampled (linear) to `wavelengths`, which they must cover.
SensitivityPrior learn_sensitivity_prior(const SpectralSet& curves, const std::vector<double>& wavelengths,
                                         const std::vector<std::string>& exclude = {});

// Camera names present in a curves set (prefix before _R/_G/_B), in file order.
std::vector<std::string> camera_names(const SpectralSet& curves);

struct PriorFit {
  Eigen::VectorXd curve;  // bands, ≥ 0, in the units that make X · curve ≈ y
  double lambda = 0;      // prior weight chosen (noise variance / prior variance)
  // Posterior standard deviation of the curve at each band (same units as `curve`): the Gaussian posterior of
  // (amplitude, components) given y, with the noise variance at its REML estimate. A point estimate can be far off
  // where the chart does not see the curve (the SG under one lamp pins ~8 of 33 directions); this says where.
  Eigen::VectorXd sdev;
  // The posterior's full covariance across bands (sdev² on its diagonal). Neighbouring bands move together, so
  // drawing curves to propagate the uncertainty into anything computed from them needs it, not only sdev.
  Eigen::MatrixXd covariance;
  double noise_sdev = 0;  // REML estimate of the RAW noise σ, in y's units
};

// argmin ‖X s − y‖² + λ Σ c_i²/sdev_i² over s = a·mean + directions·c, subject to s ≥ 0 at every band.
// λ maximises the restricted (REML) marginal likelihood of y under the Gaussian prior; the constrained problem is
// solved exactly (Lawson & Hanson's LSI → LDP → NNLS).
PriorFit fit_with_prior(const ChannelPrior& prior, const Eigen::MatrixXd& X, const Eigen::VectorXd& y);

// Credible band curve ± z·sdev, clipped at 0 below (a sensitivity is never negative). z = 1.96 is the pointwise 95 %
// interval of the Gaussian posterior.
struct CurveBand {
  Eigen::VectorXd lower, upper;
};
CurveBand credible_band(const Eigen::VectorXd& curve, const Eigen::VectorXd& sdev, double z = 1.96);

}  // namespace colorlab::analysis
