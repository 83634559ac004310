#pragma once
// Reading values out of a Rendering: a region's mean per channel, and what a channel vector means as XYZ and
// as luminance in the renderer's own units (the scale to cd/m² is applied by the comparisons).
#include <Eigen/Dense>
#include <vector>

#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/verify/compare/verification.hpp"

namespace colorlab::verify::detail {

// Throws Error(bad_data) for an empty region or one outside the image.
Eigen::VectorXd region_mean(const Rendering& r, const PixelRect& region);
// The same region moved by (dx, dy) pixels, clamped into the image (the misregistration probe).
Eigen::VectorXd shifted_mean(const Rendering& r, const PixelRect& region, int dx, int dy);

// Channels -> XYZ with Y in the renderer's luminance unit: spectral radiance through the CIE 1931 observer × 683
// (W·m⁻²·sr⁻¹·nm⁻¹ -> cd/m²), RGB through its chromaticities, XYZ as it is.
class ToXyz {
 public:
  explicit ToXyz(const Rendering& r);
  analysis::Xyz operator()(const Eigen::VectorXd& channels) const;
  const Eigen::Matrix3Xd& matrix() const { return m_; }

 private:
  Eigen::Matrix3Xd m_;  // 3 × channels
};

// RGB -> XYZ for primaries and white given as xy (SMPTE RP 177), Y of white = 1.
Eigen::Matrix3d rgb_to_xyz_matrix(const Chromaticities& c);

// Band widths of a sampled spectrum: half the distance to each neighbour on either side.
std::vector<double> band_widths(const std::vector<double>& centres);

}  // namespace colorlab::verify::detail
