#pragma once
// The rendering's own noise as an uncertainty source (issue 23, docs/verify.md "The uncertainty, source by
// source"): a Monte-Carlo renderer's region mean is itself an estimate, with a standard error the rendering shows.
// Estimated from the rendering alone, per kind of region (chart patches, LS-110 spots, floor cells):
//  - inside each region (its central 24 × 24 pixels at most) a plane is fitted per coordinate (the illumination's gradient is the scene, not noise) and
//    the residuals are the noise;
//  - the noise's spatial correlation (a pixel filter wider than a pixel, a denoiser, upsampling) from lag products of
//    the residuals pooled over every region, by the method of moments that accounts for what the plane removed
//    (lags up to 1 px, or 2 px when every region is at least 6 × 6);
//  - the noise's level relative to the value (a path tracer's estimate of direct light is the albedo times a sampled
//    form factor, so its spread scales with the value), pooled over the `neighbours` nearest regions in the image —
//    one region's few pixels give too uncertain a variance for a k = 2 band;
//  - robustly: a region whose level the median of its (at least 8) nearest regions' cannot explain — a texture, an
//    edge, a firefly: residuals that are not the noise its neighbours share — is left out of the correlation and of
//    every other region's pool, and judged by its own spread.
#include <Eigen/Dense>
#include <vector>

#include "colorlab/verify/compare/verification.hpp"

namespace colorlab::verify::detail {

struct RenderingNoise {
  // Per region: the covariance of its mean in the coordinates `to` maps a pixel's channels into. Empty when no
  // region has pixels enough to say (each needs at least 2 × 2 and more than 3 pixels beyond the plane).
  std::vector<Eigen::MatrixXd> covariance;
  double lag1_correlation = 0;  // the pooled correlation of horizontally adjacent pixels (for the record)
  std::vector<bool> left_out;   // per region: its residuals not its neighbours' noise, so not pooled into theirs
  // Whether region i's stated covariance is its own spread alone (left out, with a level of its own to state).
  bool own_level(std::size_t i) const { return !covariance.empty() && i < left_out.size() && left_out[i]; }
};

// Throws Error(bad_parameter) for `neighbours` < 1.
RenderingNoise rendering_noise(const Rendering& r, const std::vector<PixelRect>& regions, const Eigen::MatrixXd& to,
                               int neighbours);

}  // namespace colorlab::verify::detail
