#pragma once
// RGB colour spaces through lcms2 (ICC v4 colour management, D50 profile connection space).
#include <array>
#include <vector>

#include "colorlab/analysis/colorimetry.hpp"

namespace colorlab::analysis {

enum class RgbSpace {
  srgb,
  adobe_rgb_1998
};

using Rgb = std::array<double, 3>;  // encoded (gamma) values on 0..1

// XYZ relative to the ICC D50 white (Y = 100), as lcms2 delivers it.
std::vector<Xyz> rgb_to_xyz_d50(RgbSpace space, const std::vector<Rgb>& rgb);
std::vector<Rgb> xyz_d50_to_rgb(RgbSpace space, const std::vector<Xyz>& xyz);
// The dissertation's approach (a): developed camera RGB, read in its colour space, to L*a*b* D50.
std::vector<Lab> rgb_to_lab_d50(RgbSpace space, const std::vector<Rgb>& rgb);

}  // namespace colorlab::analysis
