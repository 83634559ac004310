#pragma once
// Colour differences: ΔE*ab (CIE 1976), ΔE*uv, CIEDE2000.
#include "colorlab/analysis/colorimetry.hpp"

namespace colorlab::analysis {

double delta_e76(const Lab& a, const Lab& b);
double delta_e_uv(const Luv& a, const Luv& b);
// CIEDE2000 per Sharma, Wu & Dalal (2005), parametric factors kL = kC = kH = 1 by default.
double delta_e2000(const Lab& a, const Lab& b, double kL = 1, double kC = 1, double kH = 1);

}  // namespace colorlab::analysis
