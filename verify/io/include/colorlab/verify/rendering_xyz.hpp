#pragma once
// Any Rendering as CIE XYZ (issue 23): the one colour space every comparison of a rendering starts from.
#include <array>

#include "colorlab/analysis/standard_data.hpp"
#include "colorlab/verify/rendering.hpp"

namespace colorlab::verify {

using Matrix3 = std::array<std::array<double, 3>, 3>;  // row-major: xyz = M · rgb

// RGB → XYZ from red, green, blue and white chromaticities, normalised so RGB (1,1,1) has Y = 1 (SMPTE RP 177).
// Throws bad_data for degenerate chromaticities (collinear primaries, white with y <= 0).
Matrix3 rgb_to_xyz_matrix(const Chromaticities& c);

// The rendering as an xyz Rendering (3 channels X, Y, Z):
// - spectral emissive: each band's radiance (W·m⁻²·sr⁻¹·nm⁻¹) times the CIE colour-matching functions integrated
//   over the band's box (band_edges_nm), times 683 lm/W: cd/m²; units "cd/m^2".
// - rgb: rgb_to_xyz_matrix(chromaticities), times whiteLuminance when the file gives it (units "cd/m^2"), else
//   relative with Y(white) = 1 (units empty).
// - xyz: a copy (times whiteLuminance when given).
// Reflective spectral images have no luminance without a light: Error(unsupported).
Rendering to_xyz(const Rendering& image, analysis::Observer observer = analysis::Observer::cie1931_2deg);

// Per band, the integral of x̄, ȳ, z̄ over the band's box (nm): XYZ = 683 · Σ weights[i] · L[i].
std::vector<std::array<double, 3>> band_cmf_weights(const std::vector<double>& wavelengths_nm,
                                                    analysis::Observer observer = analysis::Observer::cie1931_2deg);

}  // namespace colorlab::verify
