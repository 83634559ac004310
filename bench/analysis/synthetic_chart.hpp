#pragma once
// A chart photographed by a camera whose spectral sensitivities are known, under a given lamp: the synthetic data on
// which colorlab and ArgyllCMS are compared (docs/ACCURACY.md). No noise: the differences between models are then
// model error and metamerism, not luck.
#include <string>

#include "colorlab/analysis/regression.hpp"
#include "colorlab/analysis/spectral.hpp"

namespace colorlab::bench {

// curves: three rows (R, G, B) on their own grid. RGB = camera RAW ÷ RAW of the perfect white under the same lamp
// (white-balanced, as a profile's input would be), integrated at 1 nm over the curves' range. Reference XYZ: CIE 1931
// 2° under the lamp (colorlab's ReflectanceIntegrator), Bradford-adapted to the ICC D50 white, L*a*b* against that
// white — what an ICC input profile is asked to produce.
analysis::ChartData render_chart(const analysis::SpectralSet& reflectances, const analysis::SpectralSet& lamp,
                                 const analysis::SpectralSet& curves);

// The camera's three curves out of a collection with columns "<camera>_R/_G/_B".
analysis::SpectralSet camera_curves(const analysis::SpectralSet& collection, const std::string& camera);

}  // namespace colorlab::bench
